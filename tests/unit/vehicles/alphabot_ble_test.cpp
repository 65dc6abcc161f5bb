// The Alphabot's model over its GATT link against the fake org.bluez on a private bus, whose
// Alphabot devices serve the eight characteristics of alphabot.md §2 with a small robot behind them
// (tests/fake_bluez/fake_alphabot.hpp). Real clock; every wait is for a condition, with a deadline.
#include "engine/vehicles/alphabot.hpp"

#include "engine/transport/faulty_link.hpp"

#include <doctest/doctest.h>

#include <sdbus-c++/sdbus-c++.h>

#include "tests/fake_bluez/fake_alphabot.hpp"
#include "tests/fake_bluez/fake_bluez.hpp"
#include "tests/support/private_bus.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using namespace pitwall::alphabot;
using namespace std::chrono_literals;
using testing::FakeBluez;

namespace {

constexpr const char* kRobot = "AB:00:00:00:00:01";
using Bytes = std::vector<std::uint8_t>;

FakeBluez::Options robots(int n, int cars = 0) {
  FakeBluez::Options o;
  o.adapters = 1;
  o.cars = cars;
  o.alphabots = n;
  return o;
}

GattLinkOptions quick() {
  GattLinkOptions o;
  o.scan = 300ms;
  o.backoffMin = 20ms;
  o.backoffMax = 80ms;
  return o;
}

struct Rig {
  testing::PrivateBus bus;
  Loop loop{ClockKind::Real};
  std::unique_ptr<sdbus::IConnection> fakeConnection = sdbus::createSystemBusConnection();
  FakeBluez fake;
  GattLink* gattLink = nullptr;
  std::unique_ptr<Alphabot> link;  // the model: "link" as the tests of the old link said
  std::vector<Response> responses;
  std::vector<std::string> malformed;
  std::vector<std::pair<bool, std::string>> states;

  explicit Rig(FakeBluez::Options o, std::string address = kRobot, GattLinkOptions lo = quick(),
               std::optional<Faults> faults = std::nullopt)
      : fake(loop, *fakeConnection, std::move(o)) {
    std::string error;
    std::unique_ptr<Link> made = makeAlphabotBleLink(loop, address, lo, error);
    REQUIRE_MESSAGE(made, error);
    gattLink = static_cast<GattLink*>(made.get());
    if (faults) made = std::make_unique<FaultyLink>(std::move(made), *faults);
    AlphabotOptions options;
    options.wire = AlphabotOptions::Wire::Ble;
    link = std::make_unique<Alphabot>(loop, std::move(made), options);
    link->onResponse = [this](const Response& r) { responses.push_back(r); };
    link->onMalformed = [this](const std::string& e) { malformed.push_back(e); };
    link->onConnection = [this](bool up, const std::string& why) { states.emplace_back(up, why); };
  }

  GattLink& ble() { return *gattLink; }
  testing::FakeAlphabot& robot() { return fake.alphabot(kRobot); }

  bool waitFor(const std::function<bool()>& cond, Duration deadline = 5s) {
    return testing::runUntil(loop, cond, deadline);
  }
  bool up() {
    return waitFor([&] { return link->connected(); });
  }

  template <class T>
  std::optional<T> waitResponse(Duration deadline = 3s) {
    std::optional<T> found;
    waitFor(
        [&] {
          for (const auto& r : responses)
            if (const T* t = std::get_if<T>(&r)) found = *t;
          return found.has_value();
        },
        deadline);
    return found;
  }
};

}  // namespace

TEST_CASE("alphabot ble: the link connects to a fake Alphabot and subscribes by socket") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  CHECK(rig.fake.connected(kRobot));
  CHECK(rig.link->address() == std::string("ble:") + kRobot);
  REQUIRE(rig.states.size() == 1);
  CHECK(rig.states[0] == std::make_pair(true, std::string("connected")));
  CHECK(rig.ble().notifyAcquired());
  CHECK(rig.ble().attempts() == 1);
  CHECK(rig.link->lastError().empty());
}

TEST_CASE("alphabot ble: every request reaches the right characteristic with the right bytes") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  std::vector<Request> all = {Drive{40, -10},           MeasureDistance{300},
                              CalibrateSteering{},      CalibrateCompass{},
                              SetToggles{{0x10, 0x80}}, SetAnchor{3, 100, -50},
                              NavigateTo{200, 150},     AddObstacle{100, 100, 30, 40},
                              RemoveObstacleById{1},    RemoveObstacleAt{5, 6},
                              ClearObstacles{}};
  for (const auto& r : all) REQUIRE(rig.link->send(r));
  REQUIRE(rig.waitFor([&] { return rig.robot().writes().size() == all.size(); }));
  for (std::size_t i = 0; i < all.size(); ++i) {
    auto expected = alphabot::ble::encode(all[i]);
    REQUIRE(expected.ok());
    CAPTURE(i);
    CHECK(rig.robot().writes()[i].characteristic == expected->characteristic);
    CHECK(rig.robot().writes()[i].bytes == expected->bytes);
  }
  // spot checks of the wire against the reference, independent of the encoder
  CHECK(rig.robot().writes()[0].characteristic == alphabot::ble::Characteristic::DriveSteer);
  CHECK(rig.robot().writes()[0].bytes == Bytes{0xf6, 0x28});  // steer first, then speed
  CHECK(rig.robot().writes()[1].bytes == Bytes{0x01, 0x2c, 0x00, 0x00, 0x00});  // degree 300
  CHECK(rig.robot().malformedWrites() == 0);
  CHECK(rig.robot().speed() == 40);
  CHECK(rig.robot().steer() == -10);
}

TEST_CASE("alphabot ble: notifications become responses") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  REQUIRE(rig.link->send(MeasureDistance{0}));  // facing the far wall: x 50 → 250
  auto distance = rig.waitResponse<Distance>();
  REQUIRE(distance);
  CHECK(distance->degree == 0);
  CHECK(distance->distance == 200);
  rig.responses.clear();
  REQUIRE(rig.link->send(MeasureDistance{270}));  // degree bit 8 set both ways
  auto d270 = rig.waitResponse<Distance>();
  REQUIRE(d270);
  CHECK(d270->degree == 270);
  CHECK(d270->distance == 50);

  REQUIRE(rig.link->send(AddObstacle{150, 50, 20, 20}));
  auto registered = rig.waitResponse<ObstacleRegistered>();
  REQUIRE(registered);
  CHECK(*registered == ObstacleRegistered{1, 150, 50, 20, 20});

  REQUIRE(rig.link->send(SetAnchor{2, 10, 20}));
  auto anchor = rig.waitResponse<AnchorPosition>();
  REQUIRE(anchor);
  CHECK(*anchor == AnchorPosition{2, 10, 20});

  REQUIRE(rig.link->send(CalibrateCompass{}));
  CHECK(rig.waitResponse<CalibrationFinished>());

  REQUIRE(rig.link->query(alphabot::ble::SensorKind::Compass));
  CHECK(rig.waitResponse<Compass>() == Compass{0});
  REQUIRE(rig.link->query(alphabot::ble::SensorKind::Positioning));
  CHECK(rig.waitResponse<Position>() == Position{50, 50});
  REQUIRE(rig.link->query(alphabot::ble::SensorKind::MapSize));
  CHECK(rig.waitResponse<MapSize>() == MapSize{250, 200});

  REQUIRE(rig.link->send(SetToggles{{0x10, 0x80}}));
  CHECK(rig.waitFor([&] { return rig.link->state().robotToggles == Toggles{0x10, 0x80}; }));
  rig.robot().heartbeat();
  CHECK(rig.waitFor([&] { return rig.link->state().heartbeats == 1; }));
  CHECK(rig.malformed.empty());
}

TEST_CASE("alphabot ble: after TARGET_NAVI the path is read back from PATH_FINDING") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  // an obstacle between the robot (50, 50) and the target: the path goes round it
  REQUIRE(rig.link->send(AddObstacle{120, 50, 30, 30}));
  REQUIRE(rig.waitResponse<ObstacleRegistered>());
  REQUIRE(rig.link->send(NavigateTo{200, 50}));
  // the robot says "pending" first (count 0xFF): the link reads again until the path is there
  auto path = rig.waitResponse<Path>();
  REQUIRE(path);
  REQUIRE(path->waypoints.size() == 2);
  CHECK(path->waypoints[0] == Waypoint{120, 85});
  CHECK(path->waypoints[1] == Waypoint{200, 50});
  CHECK(rig.robot().target() == Waypoint{200, 50});
}

TEST_CASE("alphabot ble: a ping is a read of PINGCLIENT, answered with the request's time") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  REQUIRE(rig.link->send(Ping{123456789}));
  auto reply = rig.waitResponse<PingReply>();
  REQUIRE(reply);
  CHECK(reply->time == 123456789);
  CHECK(rig.robot().writes().empty());  // nothing written: a read
}

TEST_CASE("alphabot ble: a value the characteristic cannot carry is refused and nothing is sent") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  CHECK_FALSE(rig.link->send(AddObstacle{0, 0, 300, 10}));
  CHECK(rig.link->lastError().find("width 300") != std::string::npos);
  CHECK_FALSE(rig.link->send(MeasureDistance{400}));
  CHECK(rig.link->lastError().find("degree 400") != std::string::npos);
  REQUIRE(rig.link->send(ClearObstacles{}));  // and the link carries on
  REQUIRE(rig.waitFor([&] { return rig.robot().writes().size() == 1; }));
  CHECK(rig.robot().writes()[0].bytes == Bytes{0x04});
}

TEST_CASE("alphabot ble: a dropped device is reconnected and works again") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  rig.fake.drop(kRobot);
  REQUIRE(rig.waitFor([&] { return rig.states.size() >= 2; }));
  CHECK_FALSE(rig.states[1].first);
  CHECK(rig.states[1].second.find("disconnected") != std::string::npos);
  CHECK_FALSE(rig.link->send(Drive{10, 0}));  // down: refused, not queued
  CHECK(rig.link->lastError().find("not connected") != std::string::npos);
  REQUIRE(rig.waitFor([&] { return rig.link->connected(); }));
  CHECK(rig.states.back().first);
  CHECK(rig.ble().attempts() >= 2);
  CHECK(rig.fake.counters(kRobot).connects == 2);
  REQUIRE(rig.link->send(MeasureDistance{0}));
  CHECK(rig.waitResponse<Distance>());
}

TEST_CASE("alphabot ble: a vanished device is looked for with discovery, and reported missing") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  rig.fake.vanish(kRobot);
  REQUIRE(rig.waitFor([&] { return !rig.link->connected() && rig.states.size() >= 2; }));
  CHECK_FALSE(rig.states[1].first);
  CHECK_FALSE(rig.fake.exported(kRobot));
  // it does not come back (vanish is for good): the link keeps looking and says so
  CHECK(rig.waitFor([&] {
    return rig.link->lastError().find("no Alphabot with the address") != std::string::npos;
  }));
  CHECK_FALSE(rig.link->connected());
}

TEST_CASE("alphabot ble: a device that is not there gives a clear error") {
  Rig rig(robots(1), "AB:00:00:00:00:99");
  REQUIRE(rig.waitFor([&] { return !rig.states.empty(); }));
  CHECK_FALSE(rig.states[0].first);
  CHECK(rig.states[0].second ==
        "no Alphabot with the address AB:00:00:00:00:99 found on hci0 in 0.3 s: is it switched "
        "on, in range, and not connected to another host?");
  CHECK(rig.link->lastError().find(rig.states[0].second) != std::string::npos);
  CHECK_FALSE(rig.link->send(Drive{1, 1}));
  // retried, but the outage is reported once
  rig.waitFor([] { return false; }, 500ms);
  CHECK(rig.states.size() == 1);
}

TEST_CASE("alphabot ble: a device without the Alphabot characteristics is refused, naming them") {
  Rig rig(robots(0, 1), "E0:00:00:00:00:01");  // an Anki car
  REQUIRE(rig.waitFor([&] { return !rig.states.empty(); }));
  CHECK_FALSE(rig.states[0].first);
  CHECK(rig.states[0].second.find("has no Alphabot characteristic DRIVE_STEER, SENSOR") !=
        std::string::npos);
  CHECK(rig.waitFor([&] { return !rig.fake.connected("E0:00:00:00:00:01"); }));
}

TEST_CASE("alphabot ble: malformed notifications reach onMalformed and the link carries on") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  using C = alphabot::ble::Characteristic;
  rig.fake.inject(kRobot, C::Sensor, Bytes{0x81, 0xff, 0x10, 0x00, 0x00});  // degree 511
  rig.fake.inject(kRobot, C::Sensor, Bytes{0x81});                          // 1 byte of 5
  rig.fake.inject(kRobot, C::Obstacle, Bytes{0x09});                        // no such sub-command
  rig.fake.inject(kRobot, C::Calibrate, Bytes{0x00, 0x00});                 // 2 bytes of 1
  REQUIRE(rig.waitFor([&] { return rig.malformed.size() == 4; }));
  CHECK(rig.malformed[0].find("SENSOR: degree 511") != std::string::npos);
  CHECK(rig.malformed[0].find("[81 ff 10 00 00]") != std::string::npos);
  CHECK(rig.malformed[1] == "SENSOR: 1 byte, expected 5 [81]");
  CHECK(rig.malformed[2].find("OBSTACLE") != std::string::npos);
  CHECK(rig.malformed[3].find("CALIBRATE: 2 bytes, expected 1") != std::string::npos);
  CHECK(rig.link->connected());
  CHECK(rig.responses.empty());
  REQUIRE(rig.link->send(MeasureDistance{0}));
  CHECK(rig.waitResponse<Distance>());
}

TEST_CASE("alphabot ble: without AcquireNotify, StartNotify and PropertiesChanged carry answers") {
  auto o = robots(1);
  o.noAcquire = true;
  Rig rig(o);
  REQUIRE(rig.up());
  CHECK_FALSE(rig.ble().notifyAcquired());
  REQUIRE(rig.link->send(MeasureDistance{90}));
  auto d = rig.waitResponse<Distance>();
  REQUIRE(d);
  CHECK(d->degree == 90);
  rig.fake.inject(kRobot, alphabot::ble::Characteristic::Sensor, Bytes{0x81});
  CHECK(rig.waitFor([&] { return rig.malformed.size() == 1; }));
}

TEST_CASE("alphabot ble: close disconnects the robot and does not reconnect") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  rig.link->close();
  // both ends: the fake's hang-up reaches the link as BlueZ's signal, later on a loaded machine
  REQUIRE(rig.waitFor([&] { return !rig.fake.connected(kRobot) && !rig.ble().connected(); }));
  // the model closed it: its own end is no news to its subscribers
  REQUIRE(rig.states.size() == 1);
  CHECK(rig.ble().refusal() == std::string("ble:") + kRobot + ": closed");
  rig.waitFor([] { return false; }, 300ms);
  CHECK_FALSE(rig.fake.connected(kRobot));
  CHECK(rig.fake.counters(kRobot).connects == 1);
}

TEST_CASE("alphabot ble: destroying a link hangs up") {
  Rig rig(robots(1));
  REQUIRE(rig.up());
  rig.link.reset();
  CHECK(rig.waitFor([&] { return !rig.fake.connected(kRobot); }));
  CHECK(rig.fake.counters(kRobot).disconnects == 1);
}

TEST_CASE("alphabot ble: a malformed address is refused before anything starts") {
  testing::PrivateBus bus;
  Loop loop{ClockKind::Real};
  std::string error;
  CHECK_FALSE(makeAlphabotBleLink(loop, "AB:00:00:00:01", GattLinkOptions{}, error));
  CHECK(error == "'AB:00:00:00:01' is not a Bluetooth address: write it as AA:BB:CC:DD:EE:FF");
}

TEST_CASE("alphabot ble: an injected drop after a notification is a lost link, then back") {
  Rig rig(robots(1), kRobot, quick(), Faults{.dropAfterFrames = 1});
  REQUIRE(rig.up());
  REQUIRE(rig.link->send(MeasureDistance{0}));
  REQUIRE(rig.waitFor([&] { return rig.states.size() >= 3; }));
  CHECK(rig.states[1] ==
        std::make_pair(false, std::string("injected fault: dropped after 1 frames")));
  CHECK(rig.states[2].first);  // the GATT link hung up and connected again
  CHECK(rig.fake.counters(kRobot).connects == 2);
}
