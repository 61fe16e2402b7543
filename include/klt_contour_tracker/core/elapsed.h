#pragma once
/// \file elapsed.h
/// The one stopwatch behind every stage and frame time the core reports.

#include <chrono>

namespace kct {

/// Wall time since `since` (steady clock), ms.
inline double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

}  // namespace kct
