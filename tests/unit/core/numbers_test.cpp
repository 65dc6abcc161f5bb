#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "engine/core/numbers.hpp"

using namespace pitwall;

TEST_CASE("formatNumber writes numbers as people write them") {
  CHECK(formatNumber(600) == "600");
  CHECK(formatNumber(-23.5) == "-23.5");
  CHECK(formatNumber(0.25) == "0.25");
  CHECK(formatNumber(-0.0) == "0");
  CHECK(formatNumber(0.1 + 0.2) == "0.3");
  CHECK(formatNumber(70000000000.0) == "70000000000");
  CHECK(formatNumber(1e300) == "1e+300");
  CHECK(formatNumber(12.3456789, 6) == "12.3457");
  CHECK(formatNumber(std::nan("")) == "nan");
  CHECK(formatNumber(-std::numeric_limits<double>::infinity()) == "-inf");
}

TEST_CASE("outOfRange is one sentence naming the field, the value and the range") {
  CHECK(outOfRange("speed", 2000, 0, 1500, "mm/s") ==
        "speed 2000 mm/s is out of range 0..1500 mm/s");
  CHECK(outOfRange("lights mask", 300, 0, 255) == "lights mask 300 is out of range 0..255");
  CHECK(outOfRange("speed", "1e999", 0, 1500, "mm/s") ==
        "speed 1e999 mm/s is out of range 0..1500 mm/s");
  CHECK(checkRange("offset", -70, -70, 70, "mm") == std::nullopt);
  CHECK(checkRange("offset", 70.5, -70, 70, "mm") ==
        std::optional<std::string>("offset 70.5 mm is out of range -70..70 mm"));
  CHECK(checkRange("offset", std::nan(""), -70, 70, "mm").has_value());
}
