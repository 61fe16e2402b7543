#pragma once
/// \file check_range.h
/// The one range check behind every validate() of the core's parameter structs, and the one
/// text-to-number parse behind setting their fields by name.

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

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

/// `text` as a T (an arithmetic type), all of it: throws std::invalid_argument("<owner>.<name>:
/// '<text>' is not a number") for empty text, text that is not a number, trailing characters,
/// or a fraction where T is integral. The range is validate()'s (check_range).
template <typename T>
T parse_number(const char* owner, const std::string& name, const std::string& text) {
  std::istringstream in(text);
  T value{};
  in >> value;
  if (in.fail() || !(in >> std::ws).eof())
    throw std::invalid_argument(std::string(owner) + "." + name + ": '" + text.substr(0, 40) +
                                "' is not a number");
  return value;
}

}  // namespace kct
