#include "engine/vehicles/anki_car.hpp"

#include <doctest/doctest.h>

#include "engine/core/log.hpp"
#include "engine/fleet/fleet.hpp"
#include "tests/unit/capture_link.hpp"

using namespace pitwall;
using namespace pitwall::anki;
using pitwall::testing::CaptureLink;

namespace {
struct Fixture {
  Loop loop{ClockKind::Virtual};
  CaptureLink link;
  AnkiCar car{loop, link, CarIdentity{1, "skull", 9, 42}};
};
}  // namespace

TEST_CASE_FIXTURE(Fixture,
                  "connecting turns on SDK mode first, then asks for version and battery") {
  link.setConnected(true);
  REQUIRE(link.sent.size() == 3);
  CHECK(link.sent[0] == std::vector<std::uint8_t>{0x03, 0x90, 0x01, 0x01});
  CHECK(std::holds_alternative<VersionRequest>(*decode(link.sent[1])));
  CHECK(std::holds_alternative<BatteryRequest>(*decode(link.sent[2])));
  CHECK(car.state().connected);
}

TEST_CASE_FIXTURE(Fixture, "a valid setSpeed sends the drive-sdk frame and records the target") {
  link.setConnected(true);
  REQUIRE(car.setSpeed(1000, 25000));
  CHECK(link.sent.back() == std::vector<std::uint8_t>{0x06, 0x24, 0xe8, 0x03, 0xa8, 0x61, 0x00});
  CHECK(car.state().target_speed_mm_s == 1000);
}

TEST_CASE_FIXTURE(Fixture, "out-of-range commands are refused with the range and send nothing") {
  link.setConnected(true);
  auto before = link.sent.size();
  auto speed = car.setSpeed(70000);
  REQUIRE_FALSE(speed);
  CHECK(speed.error().find("0..1500") != std::string::npos);
  CHECK(speed.error().find("70000") != std::string::npos);
  auto lane = car.changeLane(250);
  REQUIRE_FALSE(lane);
  CHECK(lane.error() ==
        "offset 250 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK_FALSE(car.lights(300));
  CHECK(link.sent.size() == before);
}

TEST_CASE_FIXTURE(Fixture, "commands to a disconnected car fail with a sentence saying so") {
  auto sent = car.setSpeed(500);
  REQUIRE_FALSE(sent);
  CHECK(sent.error().find("not connected") != std::string::npos);
  CHECK(link.sent.empty());
}

TEST_CASE_FIXTURE(Fixture, "position updates update the state and reach every listener") {
  link.setConnected(true);
  int events = 0;
  Subscription heard = car.messages.connect(
      [&](const Message& m) { events += std::holds_alternative<PositionUpdate>(m); });
  int again = 0;  // a second listener (a driver world beside the run's) hears it too
  Subscription second = car.messages.connect([&](const Message&) { ++again; });
  PositionUpdate p;
  p.piece_id = 34;
  p.location_id = 7;
  p.offset_mm = -23.0f;
  p.speed_mm_s = 612;
  p.parsing_flags = 0x20;
  link.carSends(p);
  CHECK(events == 1);
  CHECK(again == 1);
  CHECK(car.state().piece == 34);
  CHECK(car.state().location == 7);
  CHECK(car.state().offset_mm == doctest::Approx(-23.0));
  CHECK(car.state().speed_mm_s == 612);
  CHECK(car.state().reverse);
  CHECK(car.state().on_track);
}

TEST_CASE_FIXTURE(Fixture, "a malformed frame is counted and reported, and the car carries on") {
  link.setConnected(true);
  std::string reported;
  Subscription heard = car.malformed.connect(
      [&](const DecodeError& e, std::span<const std::uint8_t>) { reported = e.message(); });
  link.carSendsBytes({0x10, 0x27, 0x01});
  CHECK(car.state().malformed == 1);
  CHECK(reported.find("0x27") != std::string::npos);
  link.carSends(BatteryResponse{3900});
  CHECK(car.state().battery_mv == 3900);
}

// anki-overdrive.md **Decision**: a firmware that appends a field must not lose its frames.
TEST_CASE_FIXTURE(Fixture,
                  "frames longer than their layout are applied, counted per message, and their "
                  "extra bytes kept") {
  link.setConnected(true);
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  int positions = 0;
  Subscription heard = car.messages.connect(
      [&](const Message& m) { positions += std::holds_alternative<PositionUpdate>(m); });
  // 0x27 (16) + 1 byte; 0x27 + 2 bytes; a battery response (3) + 1 byte.
  link.carSendsBytes({0x11, 0x27, 0x0e, 0x22, 0x00, 0x00, 0xb8, 0xc1, 0x58, 0x02, 0x47, 0x00, 0x00,
                      0x00, 0x00, 0x58, 0x02, 0xaa});
  link.carSendsBytes({0x12, 0x27, 0x0f, 0x22, 0x00, 0x00, 0xb8, 0xc1, 0x5a, 0x02, 0x47, 0x00, 0x00,
                      0x00, 0x00, 0x58, 0x02, 0xbb, 0xcc});
  link.carSendsBytes({0x04, 0x1b, 0x4c, 0x0f, 0x01});
  log::setSink(nullptr);

  CHECK(positions == 2);
  CHECK(car.state().piece == 34);
  CHECK(car.state().location == 15);
  CHECK(car.state().speed_mm_s == 602);
  CHECK(car.state().offset_mm == doctest::Approx(-23.0));
  CHECK(car.state().battery_mv == 3916);
  CHECK(car.state().malformed == 0);
  CHECK(car.state().frames_in == 3);
  const auto& extra = car.state().extra_bytes;
  REQUIRE(extra.size() == 2);
  CHECK(extra.at("position-update").frames == 2);
  CHECK(extra.at("position-update").last == std::vector<std::uint8_t>{0xbb, 0xcc});
  CHECK(extra.at("battery-response").frames == 1);
  CHECK(extra.at("battery-response").last == std::vector<std::uint8_t>{0x01});
  // Told once per message: which one, how many bytes, which.
  REQUIRE(logged.size() == 2);
  CHECK(logged[0].find("position-update came 1 byte longer than its layout (aa)") !=
        std::string::npos);
  CHECK(logged[1].find("battery-response came 1 byte longer than its layout (01)") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(Fixture, "a ping's round trip is measured on the engine clock") {
  link.setConnected(true);
  REQUIRE(car.ping());
  loop.after(std::chrono::milliseconds(30), [&] { link.carSends(PingResponse{}); });
  loop.run();
  REQUIRE(car.lastPingRtt());
  CHECK(*car.lastPingRtt() == doctest::Approx(0.030));
}

TEST_CASE_FIXTURE(Fixture, "delocalization and car status are tracked") {
  link.setConnected(true);
  link.carSends(SpeedUpdate{600, 1000, 580});
  CHECK(car.state().speed_mm_s == 580);
  link.carSends(Delocalized{});
  CHECK(car.state().delocalized);
  CHECK(car.state().speed_mm_s == 0);
  link.carSends(CarStatus{false, true, true, false});
  CHECK_FALSE(car.state().on_track);
  CHECK(car.state().on_charger);
  CHECK(car.state().battery_low);
}

TEST_CASE_FIXTURE(Fixture, "a lane change is under way until the offset update arrives") {
  link.setConnected(true);
  REQUIRE(car.setSpeed(600));
  REQUIRE(car.changeLane(68));
  CHECK(car.state().lane_change_target_mm == doctest::Approx(68.0));
  link.carSends(OffsetUpdate{68.0f, 0});
  CHECK_FALSE(car.state().lane_change_target_mm);
  CHECK(car.state().offset_mm == doctest::Approx(68.0));
}

TEST_CASE_FIXTURE(Fixture,
                  "a lane change ends when the car reports itself there, offset update or not") {
  link.setConnected(true);
  REQUIRE(car.setSpeed(600));
  REQUIRE(car.changeLane(23));
  REQUIRE(car.state().lane_change_target_mm);
  PositionUpdate p;
  p.piece_id = 39;
  p.offset_mm = 10.0f;  // on its way
  link.carSends(p);
  CHECK(car.state().lane_change_target_mm);
  p.offset_mm = 22.5f;  // there; its 0x2d was lost
  link.carSends(p);
  CHECK_FALSE(car.state().lane_change_target_mm);

  REQUIRE(car.changeLane(-68));
  link.carSends(Delocalized{});
  CHECK_FALSE(car.state().lane_change_target_mm);  // a car off the track changes no lane
  REQUIRE(car.changeLane(68));
  link.setConnected(false);
  CHECK_FALSE(car.state().lane_change_target_mm);  // nor one that lost its link
}

TEST_CASE_FIXTURE(Fixture,
                  "a lane change to a car that stands is refused, naming the car, its speed and "
                  "what to do; nothing is sent") {
  link.setConnected(true);
  const auto before = link.sent.size();
  auto refused = car.changeLane(23);
  REQUIRE_FALSE(refused);
  CHECK(refused.error() ==
        "car 1 (skull) stands (speed 0 mm/s); a lane change needs a moving car (real cars steer "
        "only while they roll); setSpeed first (300 mm/s or more changes lanes reliably), then "
        "changeLane");
  CHECK(link.sent.size() == before);
  CHECK_FALSE(car.state().lane_change_target_mm);

  SUBCASE("told to drive, before any report: it moves") {
    REQUIRE(car.setSpeed(600));
    CHECK(car.changeLane(23));
  }
  SUBCASE("told to stop while it still rolls: it moves; once it reports 0: refused") {
    REQUIRE(car.setSpeed(600));
    link.carSends(SpeedUpdate{600, 1000, 580});
    REQUIRE(car.stop());
    CHECK(car.changeLane(-23));  // braking, as a follower behind a slower car does
    link.carSends(SpeedUpdate{0, 12500, 0});
    const auto sent = link.sent.size();
    auto stopped = car.changeLane(23);
    REQUIRE_FALSE(stopped);
    CHECK(stopped.error().starts_with(
        "car 1 (skull) stands (speed 0 mm/s); a lane change needs a moving car"));
    CHECK(link.sent.size() == sent);
  }
  SUBCASE("driven by another controller (it reports a speed it was not told here): it moves") {
    link.carSends(SpeedUpdate{500, 1000, 480});
    CHECK(car.changeLane(23));
  }
  SUBCASE("a car that is not connected is told so, not that it stands") {
    link.setConnected(false);
    auto unconnected = car.changeLane(23);
    REQUIRE_FALSE(unconnected);
    CHECK(unconnected.error().find("is not connected") != std::string::npos);
  }
}

TEST_CASE_FIXTURE(Fixture, "halt sends the stop and then refuses every command but a disconnect") {
  link.setConnected(true);
  REQUIRE(car.setSpeed(800));
  REQUIRE(car.halt());
  Message last = link.lastSent();
  auto* stop = std::get_if<SetSpeed>(&last);
  REQUIRE(stop);
  CHECK(stop->speed_mm_s == 0);
  auto sent = link.sent.size();
  auto refused = car.setSpeed(800);
  REQUIRE_FALSE(refused);
  CHECK(refused.error() ==
        "car 1 (skull) was stopped for the end of the run and takes no more commands; set-speed "
        "was not sent");
  CHECK_FALSE(car.changeLane(23));
  CHECK_FALSE(car.send(SetLights{0x44}));
  CHECK_FALSE(car.stop());
  CHECK(link.sent.size() == sent);
  CHECK(car.halt());  // again: nothing more is sent
  CHECK(link.sent.size() == sent);
  CHECK(car.disconnect());
  CHECK(std::holds_alternative<Disconnect>(link.lastSent()));
}

TEST_CASE_FIXTURE(Fixture, "a car halted while disconnected obeys nothing once it is back") {
  REQUIRE(car.halt());
  link.setConnected(true);
  auto sent = link.sent.size();
  CHECK_FALSE(car.setSpeed(500));
  CHECK(link.sent.size() == sent);
}

TEST_CASE("a car that joins the fleet after haltAll is halted too") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet(loop);
  auto first = std::make_unique<CaptureLink>();
  first->up = true;
  fleet.add(std::move(first), CarIdentity{0, "first", 9, 1});
  fleet.haltAll();
  auto late = std::make_unique<CaptureLink>();
  CaptureLink& lateLink = *late;
  AnkiCar& car = fleet.add(std::move(late), CarIdentity{0, "late", 9, 2});
  lateLink.setConnected(true);
  CHECK(car.halted());
  CHECK_FALSE(car.setSpeed(600));
  CHECK(lateLink.sent.empty());
}

namespace {
// A link that knows where its car stands, as the simulator's does.
class PlacedLink : public CaptureLink {
 public:
  std::optional<double> knownOffset() const override { return where; }
  std::optional<double> where = -68.0;
};
}  // namespace

TEST_CASE(
    "a car starts at the offset its link knows, until it reports one; a real link knows none") {
  Loop loop{ClockKind::Virtual};
  PlacedLink placed;
  AnkiCar car{loop, placed, CarIdentity{1, "skull", 9, 42}};
  CHECK(car.state().offset_mm == -68.0);
  placed.where = 23.0;  // put elsewhere before it connects
  placed.setConnected(true);
  CHECK(car.state().offset_mm == 23.0);
  PositionUpdate p;
  p.piece_id = 39;
  p.offset_mm = 22.0f;
  placed.carSends(p);
  CHECK(car.state().offset_mm == 22.0);
  placed.where = -23.0;  // from now on the car's reports tell
  placed.setConnected(false);
  placed.setConnected(true);
  CHECK(car.state().offset_mm == 22.0);
  car.rewind();  // a replay back at its start
  CHECK(car.state().offset_mm == -23.0);

  CaptureLink real;
  AnkiCar unknown{loop, real, CarIdentity{2, "nuke", 9, 43}};
  CHECK(unknown.state().offset_mm == 0.0);
}

namespace {
// Lets `seconds` of virtual time pass.
void pass(Loop& loop, double seconds) {
  loop.after(fromSeconds(seconds), [&loop] { loop.stop(); });
  loop.run();
}
PositionUpdate at(int piece) {
  PositionUpdate p;
  p.piece_id = static_cast<std::uint8_t>(piece);
  p.speed_mm_s = 800;
  return p;
}
}  // namespace

TEST_CASE_FIXTURE(Fixture,
                  "link health: a driving car silent over two pieces has lost notifications") {
  link.setConnected(true);
  REQUIRE(car.setSpeed(800));
  link.carSends(at(17));
  pass(loop, 0.3);
  link.carSends(at(18));  // 0.3 s: as a driving car reports
  pass(loop, 1.3);
  link.carSends(at(19));  // 1.3 s at 800 mm/s: 1040 mm, a long piece's transitions apart
  CHECK(car.state().silences == 0);
  pass(loop, 2.5);
  link.carSends(at(20));  // 2.5 s of nothing while told to drive
  CHECK(car.state().silences == 1);
  CHECK(car.state().longest_silence == doctest::Approx(2.5));
  pass(loop, 0.5);
  REQUIRE(car.stop());  // told to stop 0.5 s after its last frame: a silence ends there
  pass(loop, 3);
  REQUIRE(car.setSpeed(800));
  link.carSends(at(20));
  CHECK(car.state().silences == 1);
  // not silences: a standing car says nothing; nor the time a car was away
  REQUIRE(car.stop());
  pass(loop, 5);
  link.carSends(at(20));
  REQUIRE(car.setSpeed(800));  // it starts reporting as it rolls
  pass(loop, 0.3);
  link.carSends(at(21));
  link.setConnected(false);
  pass(loop, 4);
  link.setConnected(true);
  REQUIRE(car.setSpeed(800));
  pass(loop, 0.2);
  link.carSends(at(23));
  CHECK(car.state().silences == 1);
}

TEST_CASE_FIXTURE(Fixture, "link health: the round trip of the last request the car answered") {
  CHECK(car.state().round_trip < 0);  // before any
  link.setConnected(true);            // version and battery asked now
  pass(loop, 0.04);
  link.carSends(VersionResponse{0x2b70});
  CHECK(car.state().round_trip == doctest::Approx(0.04));
  pass(loop, 0.02);
  link.carSends(BatteryResponse{3900});
  CHECK(car.state().round_trip == doctest::Approx(0.06));
  REQUIRE(car.ping());
  pass(loop, 0.1);
  link.carSends(PingResponse{});
  CHECK(car.state().round_trip == doctest::Approx(0.1));
  link.carSends(PingResponse{});  // unasked: no news
  CHECK(car.state().round_trip == doctest::Approx(0.1));
}
