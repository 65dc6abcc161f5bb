#pragma once
// Numbers in the words people read: the one formatter for a value in an error, a log line or a
// summary, and the one sentence for a value outside its range, so every layer says it the same
// way ("speed 2000 mm/s is out of range 0..1500 mm/s").
#include <optional>
#include <string>
#include <string_view>

namespace pitwall {

// A number as a script or a person writes it: 600, -23.5, 0.25, 1e+20, nan, inf (not
// 600.000000). Whole numbers below 2^53 print in full; others with up to `digits` significant
// digits (10: what a script wrote; 6: a figure in a table or a summary).
std::string formatNumber(double v, int digits = 10);

// "<what> <value>[ unit] is out of range <lo>..<hi>[ unit]". `value` is the text as given (so a
// huge or unparsed value is quoted as it came); the doubles' forms format it.
std::string outOfRange(std::string_view what, std::string_view value, double lo, double hi,
                       std::string_view unit = {});
std::string outOfRange(std::string_view what, double value, double lo, double hi,
                       std::string_view unit = {});

// nullopt when lo <= value <= hi (NaN is outside), else outOfRange's sentence.
std::optional<std::string> checkRange(std::string_view what, double value, double lo, double hi,
                                      std::string_view unit = {});

}  // namespace pitwall
