// The accepted range of every controller→vehicle command.
#include "engine/protocol/anki/limits.hpp"

#include <doctest/doctest.h>

#include <limits>

using namespace pitwall::anki;

namespace {
std::string refusal(const Message& m) {
  const auto v = limits::validate(m);
  REQUIRE(v.has_value());
  return *v;
}
}  // namespace

TEST_CASE("commands inside their ranges are accepted") {
  CHECK_FALSE(limits::validate(SetSpeed{.speed_mm_s = 1500, .accel_mm_s2 = 25000}));
  CHECK_FALSE(limits::validate(SetSpeed{.speed_mm_s = 0, .accel_mm_s2 = 0}));
  CHECK_FALSE(
      limits::validate(ChangeLane{.h_speed_mm_s = 300, .h_accel_mm_s2 = 300, .offset_mm = -70}));
  CHECK_FALSE(limits::validate(SetOffset{.offset_mm = 70}));
  CHECK_FALSE(limits::validate(ChangeLane{.offset_mm = 68}));  // the outer lanes
  CHECK_FALSE(
      limits::validate(Turn{.type = TurnType::UTurnJump, .trigger = TurnTrigger::Intersection}));
  CHECK_FALSE(limits::validate(SetConfig{.super_code_parse_mask = 0xff, .track_material = 1}));
  CHECK_FALSE(limits::validate(SdkMode{}));
  CHECK_FALSE(limits::validate(SetLights{.mask = 0xff}));
  CHECK_FALSE(limits::validate(PingRequest{}));
  LightsPattern p{.channel_count = 3, .channels = {}};
  p.channels[2] = {.channel = 5, .effect = 4, .start = 14, .end = 14, .cycles_per_10s = 255};
  CHECK_FALSE(limits::validate(p));
}

TEST_CASE("a speed out of range is refused with field, value and range") {
  CHECK(refusal(SetSpeed{.speed_mm_s = 2000, .accel_mm_s2 = 1000}) ==
        "speed 2000 mm/s is out of range 0..1500 mm/s");
  CHECK(refusal(SetSpeed{.speed_mm_s = -1}) == "speed -1 mm/s is out of range 0..1500 mm/s");
  CHECK(refusal(SetSpeed{.speed_mm_s = 500, .accel_mm_s2 = 30000}) ==
        "acceleration 30000 mm/s² is out of range 0..25000 mm/s²");
}

TEST_CASE("a lane change out of range is refused") {
  CHECK(refusal(ChangeLane{.h_speed_mm_s = 1501}) ==
        "lane-change speed 1501 mm/s is out of range 0..1500 mm/s");
  CHECK(refusal(ChangeLane{.h_accel_mm_s2 = 30000}).find("0..25000 mm/s²") != std::string::npos);
  CHECK(refusal(ChangeLane{.offset_mm = 100.5f}) ==
        "offset 100.5 mm is out of range -70..70 mm (beyond it the car leaves the road)");
}

// seed 000 §4.3.4.4: beyond ±70 mm the car leaves the road.
TEST_CASE("an offset beyond 70 mm either side is refused for lane changes and set-offset alike") {
  CHECK(refusal(ChangeLane{.offset_mm = 70.5f}) ==
        "offset 70.5 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal(ChangeLane{.offset_mm = -71}) ==
        "offset -71 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal(SetOffset{.offset_mm = 90}) ==
        "offset 90 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal(SetOffset{.offset_mm = -100}) ==
        "offset -100 mm is out of range -70..70 mm (beyond it the car leaves the road)");
}

TEST_CASE("offsets that are not finite numbers are refused") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  CHECK(refusal(SetOffset{.offset_mm = nan}) ==
        "offset nan mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal(SetOffset{.offset_mm = -inf}) ==
        "offset -inf mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal(ChangeLane{.offset_mm = inf}).find("inf mm") != std::string::npos);
}

TEST_CASE("a turn with a type or trigger outside the enum is refused") {
  CHECK(refusal(Turn{.type = static_cast<TurnType>(5)}) == "turn type 5 is out of range 0..4");
  CHECK(refusal(Turn{.trigger = static_cast<TurnTrigger>(2)}) ==
        "turn trigger 2 is out of range 0..1");
}

TEST_CASE("a lights pattern is checked channel by channel") {
  CHECK(refusal(LightsPattern{.channel_count = 0}) == "channel count 0 is out of range 1..3");
  CHECK(refusal(LightsPattern{.channel_count = 4}) == "channel count 4 is out of range 1..3");
  LightsPattern p{.channel_count = 2, .channels = {}};
  p.channels[1].channel = 6;
  CHECK(refusal(p) == "slot 2 channel 6 is out of range 0..5");
  p.channels[1] = {.effect = 5};
  CHECK(refusal(p) == "slot 2 effect 5 is out of range 0..4");
  p.channels[1] = {.start = 15};
  CHECK(refusal(p) == "slot 2 start intensity 15 is out of range 0..14");
  p.channels[1] = {.end = 20};
  CHECK(refusal(p) == "slot 2 end intensity 20 is out of range 0..14");
  // slots beyond the count are not the car's business
  p.channels[1] = {};
  p.channels[2].channel = 99;
  CHECK_FALSE(limits::validate(p));
}

TEST_CASE("a config with an unknown track material is refused") {
  CHECK(refusal(SetConfig{.track_material = 2}) == "track material 2 is out of range 0..1");
}

TEST_CASE("vehicle-to-controller messages are always valid") {
  CHECK_FALSE(limits::validate(PositionUpdate{.offset_mm = 5000, .speed_mm_s = 60000}));
  CHECK_FALSE(limits::validate(SpeedUpdate{.desired_mm_s = -30000}));
  CHECK_FALSE(limits::validate(
      LaneChangeUpdate{.current_offset_mm = std::numeric_limits<float>::quiet_NaN()}));
  CHECK_FALSE(limits::validate(CarStatus{}));
}

TEST_CASE("a raw frame with the forbidden id 0x3a is refused") {
  CHECK(refusal(Unknown{.id = 0x3a, .raw = {}}).find("0x3a") != std::string::npos);
  CHECK_FALSE(limits::validate(Unknown{.id = 0x99, .raw = {}}));
}
