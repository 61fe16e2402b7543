#pragma once
/// \file check_range.h
/// The one range check behind every validate() of the core's parameter structs.

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace kct {

/// Throws std::invalid_argument("<owner>.<name> = <value> is outside the allowed range [low,
/// high]") unless low <= value <= high; NaN and infinities are rejected too.
inline void check_range(const char* owner, const char* name, double value, double low,
                        double high) {
  if (!(value >= low && value <= high) || !std::isfinite(value)) {
    std::ostringstream message;
    message << owner << "." << name << " = " << value << " is outside the allowed range [" << low
            << ", " << high << "]";
    throw std::invalid_argument(message.str());
  }
}

}  // namespace kct
