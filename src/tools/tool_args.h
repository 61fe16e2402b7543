#pragma once
/// \file tool_args.h
/// The command-line options of the tools (`--name value` and `--flag`), parsed in one place.
/// Hand-written: a table of a dozen options does not need a library the package does not
/// already depend on (boost::program_options would add a link dependency to every tool).

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace kct_tools {

/// One option: `--name value` calls set(value); a flag (takes_value false) calls set("").
struct ToolOption {
  std::string name;
  std::function<void(const std::string&)> set;
  bool takes_value = true;
};

/// Parses argv[1..argc-1] against `options`. Returns false when -h or --help is given (the
/// caller prints its usage). Throws std::invalid_argument naming the option for an unknown
/// option, a missing value, or a value set() rejects (a bad number included).
inline bool parse_tool_options(int argc, char** argv, const std::vector<ToolOption>& options) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") return false;
    const ToolOption* option = nullptr;
    for (const ToolOption& o : options)
      if (o.name == arg) option = &o;
    if (!option) throw std::invalid_argument("unknown option " + arg);
    if (!option->takes_value) {
      option->set("");
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
    const std::string value = argv[++i];
    try {
      option->set(value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(arg + " " + value + ": " + e.what());
    } catch (const std::out_of_range&) {
      throw std::invalid_argument(arg + " " + value + ": out of range");
    }
  }
  return true;
}

/// `v` read whole by `convert` (std::stod, std::stoi...): std::invalid_argument "not a number"
/// for text that is not one or has text after it, std::out_of_range beyond the type.
template <typename T, typename Convert>
T parse_number(const std::string& v, Convert convert) {
  std::size_t used = 0;
  T value{};
  try {
    value = convert(v, &used);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("not a number");
  }
  if (used != v.size()) throw std::invalid_argument("not a number");
  return value;
}

/// set() functions storing the value in `out`.
inline std::function<void(const std::string&)> store(std::string& out) {
  return [&out](const std::string& v) { out = v; };
}
inline std::function<void(const std::string&)> store(double& out) {
  return [&out](const std::string& v) {
    out = parse_number<double>(v, [](const std::string& s, std::size_t* n) { return std::stod(s, n); });
  };
}
inline std::function<void(const std::string&)> store(long long& out) {
  return [&out](const std::string& v) {
    out = parse_number<long long>(v, [](const std::string& s, std::size_t* n) { return std::stoll(s, n); });
  };
}
inline std::function<void(const std::string&)> store(int& out) {
  return [&out](const std::string& v) {
    out = parse_number<int>(v, [](const std::string& s, std::size_t* n) { return std::stoi(s, n); });
  };
}
/// A flag (no value): sets `out` to true.
inline ToolOption flag(const std::string& name, bool& out) {
  return {name, [&out](const std::string&) { out = true; }, false};
}

}  // namespace kct_tools
