// A lap trace kept as JSON (engine/laps/trace_json.hpp): what is written reads back as the lap it
// was, and anything else — hostile, out of order, too long — is a sentence, never a lap.
#include "engine/laps/trace_json.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

using namespace pitwall::laps;
using nlohmann::json;

namespace {
LapTrace sample() {
  LapTrace t;
  t.lap = 3;
  t.time = 4.465;
  t.length = 2000;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  t.points = {
      {0, 0, 800, -68}, {1.25, 500, nan, nan}, {3.0, 1400, 820.5, 23.4}, {4.465, 2000, nan, nan}};
  t.pieceEntered = {0, 1.25, nan};
  t.pieceReported = {true, false, true};
  return t;
}
}  // namespace

TEST_CASE("laps: a trace kept as JSON reads back as the same lap") {
  const LapTrace t = sample();
  auto back = traceFromJson(json::parse(traceJson(t).dump()));
  REQUIRE(back);
  CHECK(back->lap == 3);
  CHECK(back->time == doctest::Approx(4.465));
  CHECK(back->length == doctest::Approx(2000));
  REQUIRE(back->points.size() == 4);
  CHECK(std::isnan(back->points[1].speed));
  CHECK(back->points[2].offset == doctest::Approx(23.4));
  CHECK(back->timeAt(1400) == doctest::Approx(3.0));
  REQUIRE(back->pieceEntered.size() == 3);
  CHECK(std::isnan(back->pieceEntered[2]));
  CHECK(back->pieceReported == std::vector<bool>{true, false, true});
}

TEST_CASE("laps: a kept trace that is not a whole lap is a sentence") {
  const json good = traceJson(sample());
  auto refused = [&](json j, const char* says) {
    auto r = traceFromJson(j);
    REQUIRE_FALSE(r);
    CHECK_MESSAGE(r.error().find(says) != std::string::npos, r.error());
  };
  refused(json::array(), "not a JSON object");
  refused("x", "not a JSON object");
  json j = good;
  j.erase("points");
  refused(j, "lacks its lap, time, length or points");
  j = good;
  j["time"] = -1;
  refused(j, "must be numbers above 0");
  j = good;
  j["length"] = std::numeric_limits<double>::infinity();
  refused(j, "must be numbers above 0");
  j = good;
  j["points"][2][0] = 0.5;
  refused(j, "go back in time or distance");
  j = good;
  j["points"][2] = {1, 2};
  refused(j, "is not [t, distance, speed, offset]");
  j = good;
  j["points"][2][1] = "far";
  refused(j, "other than numbers");
  j = good;
  j["points"].back()[1] = 1999;
  refused(j, "does not run from the line round to the line");
  j = good;
  j["points"] = json::array();
  for (std::size_t k = 0; k <= kMaxTracePoints; ++k)
    j["points"].push_back({static_cast<double>(k), static_cast<double>(k), nullptr, nullptr});
  refused(j, "points; it needs 2 to");
  j = good;
  j["entered"] = {0, "soon"};
  refused(j, "piece times are not numbers");
  j = good;
  j["lap"] = 1e12;  // (a number, not an integer)
  refused(j, "lacks its lap");
}
