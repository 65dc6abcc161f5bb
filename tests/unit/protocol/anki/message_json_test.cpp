// Messages as JSON: names, hex ids, every field under its struct name, optional fields left out.
#include "engine/protocol/anki/message_json.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string_view>

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

// The kinds the cases above do not show, each with every field set: the exact text `pitwall
// decode` prints and `--record` files hold (keys sorted, floats shortest, signed stays signed).
TEST_CASE("every other message kind prints every field under its struct name") {
  struct Case {
    Message message;
    std::string_view dump;
  };
  const Case cases[] = {
      {BatteryRequest{}, R"({"id":"0x1a","name":"battery-request"})"},
      {SetLights{.mask = 0x44}, R"({"id":"0x1d","mask":68,"name":"set-lights"})"},
      {ChangeLane{.h_speed_mm_s = 250,
                  .h_accel_mm_s2 = 1000,
                  .offset_mm = -68.0f,
                  .hop_intent = 1,
                  .tag = 7},
       R"({"h_accel_mm_s2":1000,"h_speed_mm_s":250,"hop_intent":1,"id":"0x25",)"
       R"("name":"change-lane","offset_mm":-68.0,"tag":7})"},
      {SetConfig{.super_code_parse_mask = 1, .track_material = 1},
       R"({"id":"0x45","name":"set-config","super_code_parse_mask":1,"track_material":1})"},
      {VersionResponse{.version = 0x2b6e},
       R"({"id":"0x19","name":"version-response","version":11118})"},
      {BatteryResponse{.millivolts = 3920},
       R"({"id":"0x1b","millivolts":3920,"name":"battery-response"})"},
      {TransitionUpdate{.piece_idx = -1,
                        .prev_piece_idx = 2,
                        .offset_mm = 23.5f,
                        .driving_direction = 1,
                        .last_recv_lane_change_id = 4,
                        .last_exec_lane_change_id = 5,
                        .last_desired_lane_change_speed_mm_s = 300,
                        .average_follow_line_drift_px = -3,
                        .had_lane_change_activity = 1,
                        .uphill_counter = 6,
                        .downhill_counter = 7,
                        .left_wheel_distance_cm = 8,
                        .right_wheel_distance_cm = 9},
       R"({"average_follow_line_drift_px":-3,"downhill_counter":7,"driving_direction":1,)"
       R"("had_lane_change_activity":1,"id":"0x29","last_desired_lane_change_speed_mm_s":300,)"
       R"("last_exec_lane_change_id":5,"last_recv_lane_change_id":4,"left_wheel_distance_cm":8,)"
       R"("name":"transition-update","offset_mm":23.5,"piece_idx":-1,"prev_piece_idx":2,)"
       R"("right_wheel_distance_cm":9,"uphill_counter":6})"},
      {IntersectionUpdate{.piece_idx = 10,
                          .offset_mm = 0.1f,
                          .intersection_code = 3,
                          .is_exiting = 1,
                          .mm_since_last_transition_bar = 120,
                          .mm_since_last_intersection_code = 45},
       R"({"id":"0x2a","intersection_code":3,"is_exiting":1,"mm_since_last_intersection_code":45,)"
       R"("mm_since_last_transition_bar":120,"name":"intersection-update","offset_mm":0.1,)"
       R"("piece_idx":10})"},
      {OffsetUpdate{.offset_mm = -23.0f, .lane_change_id = 2},
       R"({"id":"0x2d","lane_change_id":2,"name":"offset-update","offset_mm":-23.0})"},
      {SpeedUpdate{.desired_mm_s = 600, .accel_mm_s2 = -1000, .actual_mm_s = 580},
       R"({"accel_mm_s2":-1000,"actual_mm_s":580,"desired_mm_s":600,"id":"0x36",)"
       R"("name":"speed-update"})"},
      {CarStatus{
           .on_track = true, .on_charger = false, .low_battery = true, .fully_charged = false},
       R"({"fully_charged":false,"id":"0x3f","low_battery":true,"name":"car-status",)"
       R"("on_charger":false,"on_track":true})"},
      {LaneChangeUpdate{.current_offset_mm = -23.5f,
                        .target_offset_mm = 23.5f,
                        .h_speed_mm_s = 250,
                        .v_speed_mm_s = -2,
                        .lane_change_id = 3},
       R"({"current_offset_mm":-23.5,"h_speed_mm_s":250,"id":"0x41","lane_change_id":3,)"
       R"("name":"lane-change-update","target_offset_mm":23.5,"v_speed_mm_s":-2})"},
      {AutoRecoverySucceeded{}, R"({"id":"0x44","name":"auto-recovery-succeeded"})"},
      {Collision{.side = 1, .front_back = 2},
       R"({"front_back":2,"id":"0x4d","name":"collision","side":1})"},
      {CycleOvertime{.count = 2, .average_us = 70000, .max_us = 123456},
       R"({"average_us":70000,"count":2,"id":"0x86","max_us":123456,"name":"cycle-overtime"})"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.dump);
    CHECK(toJson(c.message).dump() == c.dump);
  }
}
