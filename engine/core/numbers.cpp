#include "engine/core/numbers.hpp"

#include <cmath>
#include <cstdio>

namespace pitwall {

std::string formatNumber(double v, int digits) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
  char buf[32];
  if (v == std::trunc(v) && std::fabs(v) < 9007199254740992.0)
    std::snprintf(buf, sizeof buf, "%.0f", v == 0 ? 0.0 : v);  // no "-0"
  else
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

namespace {
std::string withUnit(std::string text, std::string_view unit) {
  if (!unit.empty()) (text += ' ') += unit;
  return text;
}
}  // namespace

std::string outOfRange(std::string_view what, std::string_view value, double lo, double hi,
                       std::string_view unit) {
  return std::string(what) + " " + withUnit(std::string(value), unit) + " is out of range " +
         formatNumber(lo) + ".." + withUnit(formatNumber(hi), unit);
}

std::string outOfRange(std::string_view what, double value, double lo, double hi,
                       std::string_view unit) {
  return outOfRange(what, formatNumber(value), lo, hi, unit);
}

std::optional<std::string> checkRange(std::string_view what, double value, double lo, double hi,
                                      std::string_view unit) {
  if (value >= lo && value <= hi) return std::nullopt;
  return outOfRange(what, value, lo, hi, unit);
}

}  // namespace pitwall
