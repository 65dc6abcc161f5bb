// The vehicle side of the protocol as a simulated car speaks it (docs/simulator.md).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "engine/core/log.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/sim/code_layout.hpp"
#include "engine/sim/world.hpp"

using namespace pitwall;
using namespace pitwall::sim;
using namespace std::chrono_literals;

namespace {

struct Heard {
  double t;
  anki::Message m;
  std::size_t size = 0;  // bytes on the air
};

// One car on a track, its frames decoded and logged with their time.
struct Rig {
  Loop loop{ClockKind::Virtual};
  World world;
  SimCar& car;
  std::vector<Heard> heard;
  bool dropped = false;

  explicit Rig(CarSpec spec = {}, std::string_view layout = "oval")
      : world(
            loop,
            (layout.find(' ') == std::string_view::npos ? namedLayout(layout) : parseLayout(layout))
                .value(),
            7),
        car(world.addCar(std::move(spec))) {
    world.setSensor(
        SensorModel::Ideal);  // the protocol, code by code (sensor_test.cpp: the real model)
    car.connect(
        [this](std::span<const std::uint8_t> f) {
          auto m = anki::decode(f);
          REQUIRE(m.ok());
          heard.push_back({loop.seconds(), *m, f.size()});
        },
        [this] { dropped = true; });
  }
  void send(const anki::Message& m) { car.receive(anki::encode(m).span()); }
  void sdk() { send(anki::SdkMode{true, 1}); }
  void runUntil(double seconds) {
    loop.at(fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
  template <class T>
  std::vector<std::pair<double, T>> all() const {
    std::vector<std::pair<double, T>> out;
    for (const auto& h : heard)
      if (auto* m = std::get_if<T>(&h.m)) out.emplace_back(h.t, *m);
    return out;
  }
};

}  // namespace

TEST_CASE("a car answers ping, version and battery requests without SDK mode") {
  Rig rig(CarSpec{.name = "car", .version = 0x2b70, .battery_mv = 3950});
  rig.heard.clear();
  rig.send(anki::PingRequest{});
  rig.send(anki::VersionRequest{});
  rig.send(anki::BatteryRequest{});
  REQUIRE(rig.heard.size() == 3);
  CHECK(std::holds_alternative<anki::PingResponse>(rig.heard[0].m));
  CHECK(std::get<anki::VersionResponse>(rig.heard[1].m).version == 0x2b70);
  CHECK(std::get<anki::BatteryResponse>(rig.heard[2].m).millivolts == 3950);
}

// docs/simulator.md "Firmware families": the layouts follow the version the car answers.
TEST_CASE("a car of firmware before 0x2b6e sends the older layouts, a newer one the newer") {
  for (std::uint16_t version : {std::uint16_t{0x266e}, anki::kFirmwareDefault}) {
    const bool older = version == 0x266e;
    INFO("firmware " << version);
    Rig rig(CarSpec{.name = "car", .version = version});
    rig.sdk();
    rig.send(anki::SetSpeed{600, 1000});
    rig.runUntil(4);
    rig.send(anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
    rig.runUntil(8);
    std::vector<int> sizes, directions;
    for (const auto& h : rig.heard)
      if (auto* t = std::get_if<anki::TransitionUpdate>(&h.m)) {
        sizes.push_back(static_cast<int>(h.size));
        directions.push_back(t->driving_direction ? *t->driving_direction : -1);
      }
    REQUIRE(sizes.size() >= 4);
    CHECK(std::ranges::all_of(sizes, [&](int n) { return n == (older ? 19 : 18); }));
    if (older) {
      CHECK(directions.front() == 0);  // forward, as IBM's captured frame
      CHECK(directions.back() == 1);   // after the U-turn
    } else {
      CHECK(std::ranges::all_of(directions, [](int d) { return d == -1; }));
    }
    auto speed = rig.all<anki::SpeedUpdate>();
    REQUIRE(speed.size() == 1);
    CHECK(speed[0].second.desired_mm_s == 600);
    CHECK(speed[0].second.actual_mm_s.has_value() == !older);
    CHECK(speed[0].second.accel_mm_s2.has_value() == !older);
    rig.send(anki::VersionRequest{});
    CHECK(std::get<anki::VersionResponse>(rig.heard.back().m).version == version);
  }
}

TEST_CASE("a car reports its status when connected and when SDK mode goes on") {
  Rig rig;
  auto status = rig.all<anki::CarStatus>();
  REQUIRE(status.size() == 1);
  CHECK(status[0].second.on_track);
  CHECK(status[0].second.low_battery == false);  // the long form
  rig.sdk();
  CHECK(rig.all<anki::CarStatus>().size() == 2);
  CHECK(rig.car.truth().sdk_mode);
  CHECK(rig.car.truth().connected);
}

TEST_CASE("a car ignores driving commands until SDK mode is on") {
  Rig rig;
  rig.send(anki::SetSpeed{600, 1000});
  rig.send(anki::ChangeLane{100, 1000, 40.0f});
  rig.send(anki::SetOffset{30.0f});
  rig.send(anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
  rig.runUntil(2);
  Truth t = rig.car.truth();
  CHECK(t.speed_mm_s == 0);
  CHECK(t.target_speed_mm_s == 0);
  CHECK(t.offset_mm == 0);
  CHECK(rig.all<anki::SpeedUpdate>().empty());
  CHECK(rig.all<anki::PositionUpdate>().empty());

  rig.sdk();
  rig.send(anki::SetSpeed{600, 1000});
  rig.runUntil(4);
  CHECK(rig.car.truth().speed_mm_s == 600);
  CHECK_FALSE(rig.all<anki::PositionUpdate>().empty());
}

// anki-overdrive.md **Decision**: py-drivesdk's set_speed and stop leave out the respect-limit
// byte, and real cars obey them.
TEST_CASE("a car obeys set speed without its last byte: it drives at 500 mm/s, then stops") {
  Rig rig;
  rig.sdk();
  rig.car.receive(std::vector<std::uint8_t>{0x05, 0x24, 0xf4, 0x01, 0xf4, 0x01});
  auto ack = rig.all<anki::SpeedUpdate>();
  REQUIRE(ack.size() == 1);
  CHECK(ack[0].second.desired_mm_s == 500);
  CHECK(ack[0].second.accel_mm_s2 == 500);
  rig.runUntil(5);  // 1 s to reach 500 mm/s, then 4 s at it
  CHECK(rig.car.truth().speed_mm_s == 500);
  auto driving = rig.all<anki::PositionUpdate>();
  REQUIRE(driving.size() > 5);
  CHECK(driving.back().second.speed_mm_s == 500);
  CHECK(driving.back().second.last_desired_speed_mm_s == 500);

  rig.heard.clear();
  rig.car.receive(std::vector<std::uint8_t>{0x05, 0x24, 0x00, 0x00, 0xf4, 0x01});
  CHECK(rig.car.truth().target_speed_mm_s == 0);
  CHECK(rig.car.truth().stop_commands == 1);
  rig.runUntil(7);  // 500 mm/s at 500 mm/s² stops within 1 s
  CHECK(rig.car.truth().speed_mm_s == 0);
  auto braking = rig.all<anki::PositionUpdate>();
  REQUIRE_FALSE(braking.empty());
  CHECK(braking.back().second.speed_mm_s < 500);
  CHECK(braking.back().second.last_desired_speed_mm_s == 0);

  const double stoppedAt = rig.car.truth().lap_distance_mm;
  rig.heard.clear();
  rig.runUntil(12);
  CHECK(rig.all<anki::PositionUpdate>().empty());
  CHECK(rig.car.truth().lap_distance_mm == stoppedAt);
}

TEST_CASE("a car tells what it ignores: the bytes and why") {
  Rig rig;
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  rig.send(anki::SetSpeed{600, 1000});                                       // before SDK mode
  rig.car.receive(std::vector<std::uint8_t>{0x04, 0x24, 0xf4, 0x01, 0xf4});  // too short even so
  rig.car.receive(std::vector<std::uint8_t>{0x02, 0x99, 0x01});              // an unknown id
  rig.sdk();
  rig.send(anki::Turn{anki::TurnType::Left, anki::TurnTrigger::Immediate});
  rig.send(anki::CarStatus{true, false, {}, {}});  // a message cars send
  rig.send(anki::SetLights{0x44});                 // taken: nothing to say
  log::setSink(nullptr);

  REQUIRE(logged.size() == 5);
  auto says = [&](std::size_t i, std::initializer_list<std::string_view> parts) {
    INFO(logged[i]);
    for (auto part : parts) CHECK(logged[i].find(part) != std::string::npos);
  };
  says(0, {"ignored 06 24 58 02 e8 03 00", "set-speed needs SDK mode"});
  says(1, {"ignored 04 24 f4 01 f4", "0x24", "too short"});
  says(2, {"ignored 02 99 01", "0x99"});
  says(3, {"ignored 03 32 01 00", "intersection"});
  says(4, {"ignored 03 3f 01 00", "car-status is a message cars send"});
  CHECK(rig.car.truth().speed_mm_s == 0);
  CHECK(rig.car.truth().speed_commands == 0);
}

TEST_CASE("a stopped car sends nothing but answers") {
  Rig rig;
  rig.sdk();
  rig.heard.clear();
  rig.runUntil(30);
  CHECK(rig.heard.empty());
  CHECK(rig.loop.pendingTimers() == 0);  // an idle world does not tick
}

TEST_CASE("a set-speed is acknowledged with a speed update") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{800, 2000});
  auto updates = rig.all<anki::SpeedUpdate>();
  REQUIRE(updates.size() == 1);
  CHECK(updates[0].second.desired_mm_s == 800);
  CHECK(updates[0].second.accel_mm_s2 == 2000);
  CHECK(updates[0].second.actual_mm_s == 0);
}

TEST_CASE("a car accelerates and decelerates toward the set speed at the set acceleration") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{800, 1000});
  rig.runUntil(0.5);
  CHECK(rig.car.truth().speed_mm_s == doctest::Approx(500).epsilon(0.011));
  rig.runUntil(1.0);
  CHECK(rig.car.truth().speed_mm_s == 800);
  rig.runUntil(3.0);
  CHECK(rig.car.truth().speed_mm_s == 800);
  rig.send(anki::SetSpeed{200, 2000});
  rig.runUntil(3.15);
  CHECK(rig.car.truth().speed_mm_s == doctest::Approx(500).epsilon(0.021));
  rig.runUntil(4.0);
  CHECK(rig.car.truth().speed_mm_s == 200);
}

TEST_CASE("speed is capped at 1500 mm/s") {
  Rig rig(CarSpec{.name = "car", .offset_mm = 68});  // outer lane: 1500 mm/s stays on in the curves
  rig.sdk();
  rig.send(anki::SetSpeed{3000, 25000});
  rig.runUntil(1);
  CHECK(rig.car.truth().speed_mm_s == 1500);
  CHECK(rig.all<anki::SpeedUpdate>()[0].second.desired_mm_s == 1500);
}

TEST_CASE("a car at 600 mm/s laps the oval in lap length over speed") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{600, 25000});
  std::vector<double> lapTimes;
  int laps = 0;
  // Sample truth every tick to find when each lap is counted.
  for (double t = 0.005; t < 30; t += 0.005) {
    rig.runUntil(t);
    if (rig.car.truth().laps != laps) {
      laps = rig.car.truth().laps;
      lapTimes.push_back(rig.loop.seconds());
    }
  }
  REQUIRE(lapTimes.size() >= 4);
  double expected = rig.world.track().lapLength(0) / 600;  // ≈ 6.67 s
  for (std::size_t i = 1; i < lapTimes.size(); ++i)
    CHECK(lapTimes[i] - lapTimes[i - 1] == doctest::Approx(expected).epsilon(0.002));
}

TEST_CASE("position updates come every 140 to 230 mm with the location ids of the lane row") {
  Rig rig;  // centre lane: row 8
  rig.sdk();
  rig.send(anki::SetSpeed{600, 25000});
  rig.runUntil(14);
  auto pos = rig.all<anki::PositionUpdate>();
  REQUIRE(pos.size() > 40);
  for (std::size_t i = 1; i < pos.size(); ++i) {
    double mm = (pos[i].first - pos[i - 1].first) * 600;
    CAPTURE(i);
    CHECK(mm >= 140 - 3);  // emitted at tick time: ±3 mm at 600 mm/s
    CHECK(mm <= 230 + 3);  // a curve's row 8 (449 mm) holds 2 sections of 150 mm or more
  }
  // The location ids along one lap, piece by piece (docs/tracks.md "The code"): 34 has 2
  // sections per row, 33 one, straights 3; the curves' rows 0–7 (inner in a left curve) hold
  // 1 + 7 × 2 sections, so row 8 begins at 15.
  std::vector<std::pair<int, int>> seen;
  for (auto& [t, m] : pos) seen.emplace_back(m.piece_id, m.location_id);
  std::vector<std::pair<int, int>> lap = {
      {34, 16}, {34, 17}, {33, 8},  {36, 24}, {36, 25}, {36, 26}, {17, 15},
      {17, 16}, {18, 15}, {18, 16}, {39, 24}, {39, 25}, {39, 26}, {40, 24},
      {40, 25}, {40, 26}, {20, 15}, {20, 16}, {23, 15}, {23, 16}, {34, 16}};
  REQUIRE(seen.size() >= lap.size());
  CHECK(std::vector(seen.begin(), seen.begin() + lap.size()) == lap);
  for (auto& [t, m] : pos) {
    CHECK(m.speed_mm_s == 600);
    CHECK(m.offset_mm == 0);
    CHECK(m.parsing_flags == 0x07);
    CHECK(m.last_desired_speed_mm_s == 600);
  }
}

TEST_CASE("location ids count rows from the car's left") {
  Rig rig(CarSpec{.name = "car", .piece_index = 2, .offset_mm = -68});
  rig.sdk();
  rig.send(anki::SetSpeed{400, 25000});
  rig.runUntil(1.5);
  auto pos = rig.all<anki::PositionUpdate>();
  REQUIRE(pos.size() >= 3);
  CHECK(pos[0].second.piece_id == 36);
  CHECK(pos[0].second.location_id == 6);  // row 2 × 3 codes + first code
  CHECK(pos[1].second.location_id == 7);
  CHECK(pos[2].second.location_id == 8);
}

TEST_CASE("a transition update is sent at each piece boundary with the wheel distances") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{600, 25000});
  rig.runUntil(0.2);
  rig.heard.clear();
  double lap = rig.world.track().lapLength(0) / 600;
  rig.runUntil(0.2 + lap);
  auto tr = rig.all<anki::TransitionUpdate>();
  CHECK(tr.size() == rig.world.track().size());
  // The car starts on 34: the boundaries are 34→33, 33→36, 36→17, 17→18, 18→39, …
  std::vector<std::pair<int, int>> wheels;
  for (auto& [t, m] : tr) wheels.emplace_back(m.left_wheel_distance_cm, m.right_wheel_distance_cm);
  CHECK(wheels[1] == std::pair{22, 22});  // 33
  CHECK(wheels[2] == std::pair{56, 56});  // the straight 36
  // A left curve: the left wheel runs at 260 mm radius (408 mm), the right at 300 (471 mm).
  CHECK(wheels[3] == std::pair{41, 47});
  CHECK(wheels[4] == std::pair{41, 47});
  CHECK(tr[0].second.offset_mm == 0);
}

TEST_CASE("a lane change moves to the target offset and reports an offset update") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{500, 25000});
  rig.send(anki::ChangeLane{150, 1500, 68.0f});
  rig.runUntil(0.2);
  double mid = rig.car.truth().offset_mm;
  CHECK(mid > 0);
  CHECK(mid < 68);
  CHECK(rig.all<anki::OffsetUpdate>().empty());
  rig.runUntil(2);
  CHECK(rig.car.truth().offset_mm == 68);
  auto done = rig.all<anki::OffsetUpdate>();
  REQUIRE(done.size() == 1);
  CHECK(done[0].second.offset_mm == 68);
  CHECK(done[0].second.lane_change_id == 1);
  // 68 mm at ≤150 mm/s takes at least 0.45 s.
  CHECK(done[0].first >= 0.45);
  auto pos = rig.all<anki::PositionUpdate>();
  CHECK(pos.back().second.offset_mm == 68);
  CHECK(pos.back().second.last_desired_lane_change_speed_mm_s == 150);
}

TEST_CASE("set-offset re-bases what the car believes; lane changes are relative to it") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetOffset{23.0f});
  rig.send(anki::SetSpeed{500, 25000});
  rig.send(anki::ChangeLane{200, 2000, 68.0f});
  rig.runUntil(2);
  CHECK(rig.car.truth().offset_mm == doctest::Approx(45));  // moved by 68 − 23
  auto done = rig.all<anki::OffsetUpdate>();
  REQUIRE(done.size() == 1);
  CHECK(done[0].second.offset_mm == 68);  // as the car believes it
}

TEST_CASE("cancel lane change stops the lateral move where it is") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{500, 25000});
  rig.send(anki::ChangeLane{100, 1000, -60.0f});
  rig.runUntil(0.3);
  rig.send(anki::CancelLaneChange{});
  double there = rig.car.truth().offset_mm;
  CHECK(there < 0);
  rig.runUntil(2);
  CHECK(rig.car.truth().offset_mm == there);
  CHECK(rig.all<anki::OffsetUpdate>().empty());
}

TEST_CASE("a U-turn reverses the car: pieces run backwards and positions carry flag 0x20") {
  Rig rig(CarSpec{.name = "car", .piece_index = 2, .distance_mm = 200, .offset_mm = -68});
  rig.sdk();
  rig.send(anki::SetSpeed{400, 25000});
  rig.runUntil(0.1);
  rig.send(anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
  rig.heard.clear();
  rig.runUntil(2.5);
  auto pos = rig.all<anki::PositionUpdate>();
  REQUIRE(pos.size() >= 5);
  for (auto& [t, m] : pos) CHECK((m.parsing_flags & 0x20) == 0x20);
  // Backwards on 36, then 33 and 34: the car is now at +68 in its own frame, but the ids are
  // the piece's (seed 000 §4.5.1: the same from either side): row 2 (−68 mm), and the first
  // section it passes backwards from 0.4 of the piece is section 0.
  CHECK(pos[0].second.piece_id == 36);
  CHECK(pos[0].second.location_id == 2 * 3 + 0);
  CHECK(pos[0].second.offset_mm == doctest::Approx(68));
  std::vector<int> pieces;
  for (auto& [t, m] : pos)
    if (pieces.empty() || pieces.back() != m.piece_id) pieces.push_back(m.piece_id);
  CHECK(pieces == std::vector<int>{36, 33, 34, 23});
  CHECK(rig.car.truth().laps == 0);  // crossing the finish backwards is not a lap
}

TEST_CASE("battery drains while driving and low battery is reported below 3600 mV") {
  Rig rig(CarSpec{.name = "car", .offset_mm = 68, .battery_mv = 3604});
  rig.sdk();
  rig.send(anki::SetSpeed{1500, 25000});
  // 500 mV per 20 min at 1500 mm/s: 4 mV take 9.6 s.
  rig.runUntil(9.0);
  CHECK(rig.car.truth().battery_mv == 3600);
  CHECK(rig.all<anki::CarStatus>().back().second.low_battery == false);
  rig.runUntil(11.0);
  auto status = rig.all<anki::CarStatus>();
  CHECK(status.back().second.low_battery == true);
  CHECK(status.back().second.on_track == true);
  rig.send(anki::BatteryRequest{});
  CHECK(std::get<anki::BatteryResponse>(rig.heard.back().m).millivolts == 3599);
}

TEST_CASE("a disconnect frame drops the connection and the car stops") {
  Rig rig;
  rig.sdk();
  rig.send(anki::SetSpeed{800, 25000});
  rig.runUntil(1);
  rig.send(anki::Disconnect{});
  CHECK(rig.dropped);
  CHECK_FALSE(rig.car.truth().connected);
  CHECK_FALSE(rig.car.truth().sdk_mode);
  auto before = rig.heard.size();
  rig.runUntil(3);
  CHECK(rig.car.truth().speed_mm_s == 0);
  CHECK(rig.heard.size() == before);
}

TEST_CASE("a car advertises its model, identifier, version and name") {
  Loop loop(ClockKind::Virtual);
  World world(loop, namedLayout("oval").value(), 1);
  SimCar& a = world.addCar({.name = "Blue", .model_id = 9, .identifier = 0x01020304});
  SimCar& b = world.addCar({});
  CHECK(a.manufacturerData() ==
        std::vector<std::uint8_t>{0xBE, 0xEF, 0x00, 9, 0x01, 0x02, 0x03, 0x04});
  CHECK(b.identifier() != 0);
  CHECK(b.identifier() != a.identifier());
  auto name = a.localName();
  REQUIRE(name.size() == 13);
  CHECK(name[1] == 0x70);
  CHECK(name[2] == 0x2b);
  CHECK(std::string(name.begin() + 8, name.end() - 1) == "Blue");
  CHECK(name.back() == 0);
}

TEST_CASE(
    "on a custom track a car reports the design's piece ids and every location id of its row") {
  // docs/tracks.md: one code section per 150 mm of a row; ids count the rows left to right in
  // the piece's forward direction, and a car driving backwards reads the same ids.
  const char* layout =
      "start S:60,len=440 L:61,r=400,deg=45 L:61,r=400,deg=45 L:61,r=400,deg=45 "
      "L:61,r=400,deg=45 S:60,len=440 S:36 L:62,r=200,deg=90 S:64,len=400 L:62,r=200,deg=90";
  for (double offset : {-68.0, -23.0, 23.0, 68.0})
    for (bool backwards : {false, true}) {
      CAPTURE(offset);
      CAPTURE(backwards);
      Rig rig(CarSpec{.name = "car", .piece_index = 2, .offset_mm = offset}, layout);
      rig.sdk();
      if (backwards) rig.send(anki::Turn{anki::TurnType::UTurn, anki::TurnTrigger::Immediate});
      rig.send(anki::SetSpeed{500, 25000});
      rig.heard.clear();
      rig.runUntil(12);  // more than a lap (≈ 4.3 m at 500 mm/s)
      const Track& track = rig.world.track();
      // What a lap must show: piece by piece in driving order, the row's ids in driving order.
      const double pieceOffset = rig.car.truth().offset_mm;  // the track frame's offset
      std::vector<std::pair<int, int>> expected;
      const std::size_t n = track.size();
      for (std::size_t k = 0; k < n; ++k) {
        std::size_t i = backwards ? (2 + n - 1 - k) % n : (2 + k) % n;
        const Piece& p = track.piece(i);
        CodeLayout code = codeLayout(p);
        const CodeRow* row = nullptr;
        for (const CodeRow& r : code.rows)
          if (std::abs(r.offset_mm - pieceOffset) <= 6) row = &r;
        REQUIRE(row);
        for (int j = 0; j < row->sections; ++j)
          expected.emplace_back(p.id, row->locationOf(backwards ? row->sections - 1 - j : j));
      }
      std::vector<std::pair<int, int>> seen;
      for (auto& [t, m] : rig.all<anki::PositionUpdate>())
        seen.emplace_back(m.piece_id, m.location_id);
      // the car starts inside piece 2 (and turns there): compare from its next piece on
      auto firstOther = std::find_if(seen.begin(), seen.end(),
                                     [&](auto& e) { return e.first != seen.front().first; });
      REQUIRE(firstOther != seen.end());
      std::vector<std::pair<int, int>> lap(firstOther, seen.end());
      auto from =
          std::find_if(expected.begin(), expected.end(), [&](auto& e) { return e == lap.front(); });
      REQUIRE(from != expected.end());
      std::rotate(expected.begin(), from, expected.end());
      REQUIRE(lap.size() >= expected.size());
      lap.resize(expected.size());
      CHECK(lap == expected);
    }
}
