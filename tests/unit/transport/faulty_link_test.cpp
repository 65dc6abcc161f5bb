// Fault injection the same way for every device: a FaultyLink around the simulator link of an
// Anki car, the TCP link of a MindRoad robot and of an Alphabot. Each model reports the injected
// fault through its normal paths: the refusal sentence of a command, a lost connection.
#include "engine/transport/faulty_link.hpp"

#include <doctest/doctest.h>

#include "engine/core/log.hpp"
#include "engine/sim/alphabot_server.hpp"
#include "engine/sim/mindroad_robot_server.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/sim_link.hpp"
#include "engine/vehicles/alphabot.hpp"
#include "engine/vehicles/anki_car.hpp"
#include "engine/vehicles/mindroad_robot.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
using pitwall::testing::runUntil;

namespace {

struct QuietLog {
  log::Level before = log::level();
  QuietLog() { log::setLevel(log::Level::Off); }
  ~QuietLog() { log::setLevel(before); }
};

struct AnkiRig {
  QuietLog quiet;
  Loop loop{ClockKind::Virtual};
  sim::World world{loop, sim::namedLayout("oval").value(), 3};
  sim::SimCar& simCar = world.addCar({.name = "car", .identifier = 0x00c0ffee});
  SimLink sim{loop, simCar, 5ms};
  FaultyLink link;
  AnkiCar car{loop, link, CarIdentity{1, "skull", 9, 42}};
  std::vector<std::pair<bool, std::string>> states;
  Subscription watch;

  explicit AnkiRig(Faults faults) : link(sim, faults) {
    watch = car.connectionChanged.connect(
        [this](bool up, const std::string& why) { states.emplace_back(up, why); });
    sim.connect();
  }
};

}  // namespace

TEST_CASE("faults: the Nth send of an Anki car fails, and its command says so") {
  AnkiRig rig(Faults{.failSend = 4});  // 1–3: SDK mode, version and battery on connecting
  REQUIRE(runUntil(rig.loop, [&] { return rig.car.state().connected; }));
  auto refused = rig.car.setSpeed(500);
  REQUIRE_FALSE(refused);
  CHECK(refused.error() == "car 1 (skull): set-speed was not sent: injected fault: send 4 failed");
  CHECK(rig.car.setSpeed(500));  // the next one goes
}

TEST_CASE("faults: an Anki car's link dropped after N frames is a lost connection") {
  AnkiRig rig(Faults{.dropAfterFrames = 2});
  REQUIRE(runUntil(rig.loop, [&] { return rig.states.size() == 2; }));
  CHECK(rig.states[0] == std::make_pair(true, std::string("connected")));
  CHECK(rig.states[1] ==
        std::make_pair(false, std::string("injected fault: dropped after 2 frames")));
  CHECK_FALSE(rig.car.state().connected);
}

TEST_CASE("faults: a refused connection of an Anki car is a failed attempt") {
  AnkiRig rig(Faults{.refuseConnects = 1});
  REQUIRE(runUntil(rig.loop, [&] { return !rig.states.empty(); }));
  CHECK(rig.states[0] ==
        std::make_pair(false, std::string("injected fault: connection 1 refused")));
  CHECK_FALSE(rig.car.state().connected);
}

namespace {

struct MindroadRig {
  QuietLog quiet;
  Loop loop{ClockKind::Real};
  sim::MindroadRobotServer server;
  MindroadOptions options;
  FaultyLink* faulty = nullptr;
  std::unique_ptr<MindroadRobot> robot;
  int contacts = 0;
  std::vector<std::string> lost;

  static sim::MindroadServerOptions serverOptions(bool udp) {
    sim::MindroadServerOptions o;
    o.udp = udp;
    return o;
  }

  explicit MindroadRig(Faults faults, bool udp = false) : server(loop, serverOptions(udp)) {
    options.port = server.port();
    options.udp = udp;
    options.backoffFirst = 0.05;
    auto link = std::make_unique<FaultyLink>(makeMindroadLink(loop, options), faults);
    faulty = link.get();
    robot = std::make_unique<MindroadRobot>(loop, std::move(link), options);
    robot->onContact = [this] { ++contacts; };
    robot->onLost = [this](const std::string& reason) { lost.push_back(reason); };
  }
  ~MindroadRig() { robot->close(); }
};

}  // namespace

TEST_CASE("faults: a MindRoad robot's link dropped after its K is lost contact, then regained") {
  MindroadRig rig(Faults{.dropAfterFrames = 1});
  REQUIRE(runUntil(rig.loop, [&] { return rig.contacts == 2; }));
  REQUIRE(rig.lost.size() == 1);
  CHECK(rig.lost[0] == "injected fault: dropped after 1 frames");
  CHECK(rig.robot->connected());
}

TEST_CASE("faults: a MindRoad robot's refused connections are one outage, then contact") {
  MindroadRig rig(Faults{.refuseConnects = 2});
  REQUIRE(runUntil(rig.loop, [&] { return rig.contacts == 1; }));
  REQUIRE(rig.lost.size() == 1);  // once per outage
  CHECK(rig.lost[0] == "injected fault: connection 1 refused");
}

TEST_CASE("faults: over UDP too, a dropped link is lost contact, then regained") {
  MindroadRig rig(Faults{.dropAfterFrames = 1}, /*udp=*/true);
  REQUIRE(runUntil(rig.loop, [&] { return rig.contacts == 2; }));
  REQUIRE(rig.lost.size() == 1);
  CHECK(rig.lost[0] == "injected fault: dropped after 1 frames");
  CHECK(rig.robot->connected());
}

TEST_CASE("faults: over UDP, a failed send is refused and a command says why") {
  MindroadRig rig(Faults{}, /*udp=*/true);
  REQUIRE(runUntil(rig.loop, [&] { return rig.contacts == 1; }));
  rig.faulty->faults().failSend = rig.faulty->sends() + 1;
  const auto before = rig.robot->instructionsSent();
  auto sent = rig.robot->stop();
  REQUIRE_FALSE(sent);
  CHECK(sent.error() == "mindroad udp 127.0.0.1:" + std::to_string(rig.server.port()) +
                            ": stop was not sent: injected fault: send " +
                            std::to_string(rig.faulty->sends()) + " failed");
  CHECK(rig.robot->instructionsSent() == before);  // not counted as sent
  CHECK(rig.robot->stop());                        // the next one goes
}

TEST_CASE("faults: a failed send to a MindRoad robot is refused by its link") {
  MindroadRig rig(Faults{});
  REQUIRE(runUntil(rig.loop, [&] { return rig.contacts == 1; }));
  rig.faulty->faults().failSend = rig.faulty->sends() + 1;
  CHECK_FALSE(rig.faulty->send(mindroad::encode(mindroad::Stop{}).span()));
  CHECK(rig.robot->link().refusal().find("injected fault: send") == 0);
}

namespace {

struct AlphabotRig {
  QuietLog quiet;
  Loop loop{ClockKind::Real};
  sim::alphabot::Robot simRobot{sim::alphabot::defaultRoom()};
  sim::alphabot::RobotServer server{loop, simRobot, "127.0.0.1", 0};
  std::unique_ptr<Alphabot> robot;
  std::vector<std::pair<bool, std::string>> states;
  int responses = 0;

  explicit AlphabotRig(Faults faults) {
    auto link = std::make_unique<FaultyLink>(
        makeAlphabotTcpLink(loop, "127.0.0.1", server.port(), 3.0), faults);
    robot = std::make_unique<Alphabot>(loop, std::move(link));
    robot->onConnection = [this](bool up, const std::string& why) { states.emplace_back(up, why); };
    robot->onResponse = [this](const alphabot::Response&) { ++responses; };
  }
};

}  // namespace

TEST_CASE("faults: the Nth send to an Alphabot fails, and its command says so") {
  AlphabotRig rig(Faults{.failSend = 1});
  REQUIRE(runUntil(rig.loop, [&] { return rig.robot->connected(); }));
  auto refused = rig.robot->drive(10, 0);
  REQUIRE_FALSE(refused);
  CHECK(refused.error() == "alphabot tcp:127.0.0.1:" + std::to_string(rig.server.port()) +
                               ": nothing sent: injected fault: send 1 failed");
  CHECK(rig.robot->drive(10, 0));
}

TEST_CASE("faults: an Alphabot's link dropped after a frame is a lost connection, then back") {
  AlphabotRig rig(Faults{.dropAfterFrames = 1});
  REQUIRE(runUntil(rig.loop, [&] { return rig.robot->connected(); }));
  REQUIRE(rig.robot->measureDistance(0));
  REQUIRE(runUntil(
      rig.loop, [&] { return rig.states.size() == 3; }, 5s));
  CHECK(rig.responses == 1);
  CHECK(rig.states[1] ==
        std::make_pair(false, std::string("injected fault: dropped after 1 frames")));
  CHECK(rig.states[2].first);  // the link reconnected by itself
}
