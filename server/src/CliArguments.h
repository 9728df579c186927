#pragma once
// Flag parsing shared by the `devsurf` subcommands (private to server/src).

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

namespace devsurf::server::cli {

/// The value after the flag at args[i] (advancing i). @throws std::invalid_argument if missing.
inline const std::string& flagValue(const std::vector<std::string>& args, std::size_t& i) {
  if (i + 1 >= args.size()) throw std::invalid_argument(args[i] + ": missing value");
  return args[++i];
}

/// An integer flag value in [lo, hi]. @throws std::invalid_argument naming the flag.
inline long parseNumber(const std::string& flag, const std::string& value, long lo, long hi) {
  std::size_t used = 0;
  long n = 0;
  try {
    n = std::stol(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || n < lo || n > hi)
    throw std::invalid_argument(flag + ": expected an integer from " + std::to_string(lo) + " to " +
                                std::to_string(hi) + ", got \"" + value + "\"");
  return n;
}

/// A positive finite length flag value. @throws std::invalid_argument naming the flag.
inline double parseLength(const std::string& flag, const std::string& value) {
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || !std::isfinite(x) || x <= 0.0)
    throw std::invalid_argument(flag + ": expected a positive length, got \"" + value + "\"");
  return x;
}

/// A fraction from 0 to 1, or a percentage from 0% to 100% ("0.5", "50%"). @throws
/// std::invalid_argument naming the flag.
inline double parseFraction(const std::string& flag, const std::string& value) {
  const bool percent = !value.empty() && value.back() == '%';
  const std::string number = percent ? value.substr(0, value.size() - 1) : value;
  std::size_t used = 0;
  double x = -1.0;
  try {
    x = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (percent) x /= 100.0;
  if (number.empty() || used != number.size() || !(x >= 0.0 && x <= 1.0))
    throw std::invalid_argument(flag + ": expected a fraction from 0 to 1 or a percentage from 0% to 100%, got \"" +
                                value + "\"");
  return x;
}

/// A --log-level value. @throws std::invalid_argument naming the flag and the levels.
inline spdlog::level::level_enum parseLogLevel(const std::string& flag, const std::string& value) {
  const spdlog::level::level_enum level = spdlog::level::from_str(value);
  if (level == spdlog::level::off && value != "off")
    throw std::invalid_argument(flag + ": expected trace, debug, info, warn, error, critical or off, got \"" + value + "\"");
  return level;
}

}  // namespace devsurf::server::cli
