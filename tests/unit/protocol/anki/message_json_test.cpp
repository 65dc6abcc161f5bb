// Messages as JSON: names, hex ids, every field under its struct name, optional fields left out.
#include "engine/protocol/anki/message_json.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

using namespace pitwall::anki;
using nlohmann::json;

TEST_CASE("a position update becomes an object with its name, hex id and every field") {
  const json j = toJson(PositionUpdate{.location_id = 14,
                                       .piece_id = 36,
                                       .offset_mm = -23.5f,
                                       .speed_mm_s = 600,
                                       .parsing_flags = 0x47,
                                       .last_recv_lane_change_id = 2,
                                       .last_exec_lane_change_id = 3,
                                       .last_desired_lane_change_speed_mm_s = 300,
                                       .last_desired_speed_mm_s = 650});
  CHECK(j == json::parse(R"({"name": "position-update", "id": "0x27", "location_id": 14,
      "piece_id": 36, "offset_mm": -23.5, "speed_mm_s": 600, "parsing_flags": 71,
      "last_recv_lane_change_id": 2, "last_exec_lane_change_id": 3,
      "last_desired_lane_change_speed_mm_s": 300, "last_desired_speed_mm_s": 650})"));
}

TEST_CASE("a float field shows the shortest decimal that reads back to it") {
  CHECK(toJson(SetOffset{.offset_mm = 0.1f})["offset_mm"].dump() == "0.1");
  CHECK(toJson(SetOffset{.offset_mm = -68.0f})["offset_mm"].dump() == "-68.0");
}

TEST_CASE("a float that JSON cannot hold becomes null") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(toJson(OffsetUpdate{.offset_mm = nan})["offset_mm"].is_null());
}

TEST_CASE("optional fields appear only when present") {
  TransitionUpdate t;
  CHECK_FALSE(toJson(t).contains("driving_direction"));
  t.driving_direction = 1;
  CHECK(toJson(t)["driving_direction"] == 1);

  IntersectionUpdate i;
  CHECK_FALSE(toJson(i).contains("mm_since_last_intersection_code"));
  i.mm_since_last_intersection_code = 45;
  CHECK(toJson(i)["mm_since_last_intersection_code"] == 45);

  const json short_status =
      toJson(CarStatus{.on_track = true, .low_battery = {}, .fully_charged = {}});
  CHECK(short_status["on_track"] == true);
  CHECK_FALSE(short_status.contains("low_battery"));
  CHECK_FALSE(short_status.contains("fully_charged"));
  CHECK(toJson(CarStatus{.low_battery = true, .fully_charged = false})["fully_charged"] == false);
}

TEST_CASE("enum fields are words, and values outside the enum stay numbers") {
  const json uturn = toJson(Turn{.type = TurnType::UTurn, .trigger = TurnTrigger::Immediate});
  CHECK(uturn["type"] == "uturn");
  CHECK(uturn["trigger"] == "immediate");
  const json jump = toJson(Turn{.type = TurnType::UTurnJump, .trigger = TurnTrigger::Intersection});
  CHECK(jump["type"] == "uturn-jump");
  CHECK(jump["trigger"] == "intersection");
  CHECK(toJson(Turn{.type = static_cast<TurnType>(9)})["type"] == 9);
}

TEST_CASE("an unknown message shows its whole frame as hex bytes") {
  Unknown u{.id = 0x99, .raw = {}};
  u.raw.bytes = {0x03, 0x99, 0x01, 0xab};
  u.raw.length = 4;
  CHECK(toJson(u) == json::parse(R"({"name": "unknown", "id": "0x99", "raw": "03 99 01 ab"})"));
}

TEST_CASE("a lights pattern lists the channels in use") {
  LightsPattern p{.channel_count = 1, .channels = {}};
  p.channels[0] = {.channel = 4, .effect = 2, .start = 0, .end = 14, .cycles_per_10s = 20};
  p.channels[1] = {.channel = 5};
  const json j = toJson(p);
  CHECK(j["channel_count"] == 1);
  CHECK(j["channels"] == json::parse(R"([{"channel": 4, "effect": 2, "start": 0, "end": 14,
      "cycles_per_10s": 20}])"));
}

TEST_CASE("message names and ids of both directions come through") {
  CHECK(toJson(SdkMode{}) == json::parse(R"({"name": "sdk-mode", "id": "0x90", "on": true,
      "flags": 1})"));
  CHECK(toJson(SetSpeed{.speed_mm_s = 500, .accel_mm_s2 = 1000}) ==
        json::parse(R"({"name": "set-speed", "id": "0x24", "speed_mm_s": 500,
      "accel_mm_s2": 1000, "respect_limit": false})"));
  CHECK(toJson(Disconnect{}) == json::parse(R"({"name": "disconnect", "id": "0x0d"})"));
  CHECK(toJson(CycleOvertime{.count = 2, .average_us = 10, .max_us = 40})["max_us"] == 40);
}
