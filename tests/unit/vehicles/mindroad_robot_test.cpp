// The MindRoad robot model over its socket link, against the simulated robot over real loopback
// sockets, on one real-time loop: handshake, keep-alive and watchdog, TCP and UDP, a robot that
// disappears and comes back, and validation at the edge.
#include "engine/vehicles/mindroad_robot.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "engine/core/log.hpp"
#include "engine/sim/mindroad_robot_server.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;
using sim::MindroadRobotServer;
using sim::MindroadServerOptions;

namespace {

struct Fixture {
  Loop loop{ClockKind::Real};
  std::unique_ptr<MindroadRobotServer> robot;
  std::unique_ptr<MindroadRobot> client;
  int contacts = 0;
  std::vector<std::string> lost;
  std::vector<std::string> robotEvents;

  log::Level logLevel = log::level();
  Fixture() { log::setLevel(log::Level::Off); }
  ~Fixture() {
    if (client) client->close();
    log::setLevel(logLevel);
  }

  void startRobot(MindroadServerOptions o = {}) {
    robot = std::make_unique<MindroadRobotServer>(loop, o);
    robot->onChange = [this](const std::string& e, const std::string&) {
      robotEvents.push_back(e);
    };
  }
  void startClient(MindroadOptions o) {
    client = std::make_unique<MindroadRobot>(loop, makeMindroadLink(loop, o), o);
    client->onContact = [this] { ++contacts; };
    client->onLost = [this](const std::string& reason) { lost.push_back(reason); };
  }
  MindroadOptions options(bool udp = false) {
    MindroadOptions o;
    o.port = robot->port();
    o.udp = udp;
    return o;
  }
  bool waitContact(int n = 1) {
    return runUntil(loop, [&] { return contacts >= n; });
  }
  const sim::MindroadRobotState& state() { return robot->robot().state(); }
};

}  // namespace

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: the client sends contact until K arrives, then reports onContact") {
  MindroadServerOptions o;
  o.robot.ignoreContacts = 2;  // the seed's example gets its answer on the third try
  startRobot(o);
  startClient(options());
  REQUIRE(waitContact());
  CHECK(client->connected());
  CHECK(client->contactsSent() >= 3);
  CHECK(state().ignored == 2);
  CHECK(state().contact);
  CHECK(lost.empty());
}

TEST_CASE_FIXTURE(Fixture, "mindroad: steering reaches the robot and drives its body") {
  startRobot();
  startClient(options());
  REQUIRE(waitContact());
  REQUIRE(client->steer(127, 0));
  REQUIRE(runUntil(loop, [&] { return state().steerX == 127; }));
  REQUIRE(runUntil(loop, [&] { return state().x > 0.05; }));
  REQUIRE(client->click(80, 60));
  REQUIRE(client->buttons(1));
  REQUIRE(client->pictureMode("filter"));
  REQUIRE(runUntil(loop, [&] { return state().picture == mindroad::Picture::Filter; }));
  CHECK(state().clickX == 80);
  CHECK(state().mode == "automatic");
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: keep-alive pings hold contact well beyond the watchdog period") {
  MindroadServerOptions o;
  o.robot.watchdog = 0.3;
  startRobot(o);
  auto c = options();
  c.watchdog = 0.3;
  startClient(c);
  REQUIRE(waitContact());
  REQUIRE(client->steer(60, 0));
  runFor(loop, std::chrono::milliseconds(1000));
  CHECK(state().contact);
  CHECK(state().moving());
  CHECK(std::count(robotEvents.begin(), robotEvents.end(), "watchdog") == 0);
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: without pings the robot stops by its watchdog; a new contact drives") {
  MindroadServerOptions o;
  o.robot.watchdog = 0.15;
  startRobot(o);
  auto c = options();
  c.watchdog = 0.15;
  c.probeInterval = 0.2;
  startClient(c);
  REQUIRE(waitContact());
  REQUIRE(client->steer(60, 0));
  REQUIRE(runUntil(loop, [&] { return state().moving(); }));
  client->pauseKeepAlive(true);
  REQUIRE(runUntil(loop, [&] { return !state().contact; }));
  CHECK_FALSE(state().moving());
  CHECK(state().lastStop.find("watchdog") != std::string::npos);
  REQUIRE(client->steer(60, 0));  // the robot waits for contact: this is ignored
  REQUIRE(runUntil(loop, [&] { return state().ignored >= 1; }));
  CHECK_FALSE(state().moving());
  client->pauseKeepAlive(false);  // the next contact probe renews contact
  REQUIRE(runUntil(loop, [&] { return state().contact; }));
  REQUIRE(client->steer(60, 0));
  REQUIRE(runUntil(loop, [&] { return state().moving(); }));
  CHECK(lost.empty());
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: over UDP the handshake, steering and keep-alive work the same") {
  MindroadServerOptions o;
  o.udp = true;
  o.robot.ignoreContacts = 1;
  startRobot(o);
  startClient(options(true));
  REQUIRE(waitContact());
  REQUIRE(client->steer(-128, 64));
  REQUIRE(runUntil(loop, [&] { return state().steerX == -128 && state().steerY == 64; }));
  runFor(loop, std::chrono::milliseconds(800));
  CHECK(state().contact);
  CHECK(state().ignored == 1);
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: a TCP robot that disappears is reported once, then found again") {
  startRobot();
  const auto port = robot->port();
  startClient(options());
  REQUIRE(waitContact());
  robot.reset();  // the robot is gone: its sockets close
  REQUIRE(runUntil(loop, [&] { return !lost.empty(); }));
  CHECK(lost[0] == "tcp 127.0.0.1:" + std::to_string(port) + " closed the connection");
  CHECK_FALSE(client->connected());
  auto refused = client->steer(10, 0);
  REQUIRE_FALSE(refused.ok());
  CHECK(refused.error().find("has no contact") != std::string::npos);
  runFor(loop, std::chrono::milliseconds(1200));  // attempts at 0.5 s and 1.5 s fail: one report
  CHECK(lost.size() == 1);
  MindroadServerOptions o;
  o.port = port;
  startRobot(o);
  REQUIRE(runUntil(
      loop, [&] { return contacts == 2; }, std::chrono::seconds(6)));
  REQUIRE(client->steer(10, 0));
  REQUIRE(runUntil(loop, [&] { return state().moving(); }));
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: a UDP robot that disappears is seen by the missing K to a probe") {
  MindroadServerOptions o;
  o.udp = true;
  startRobot(o);
  auto c = options(true);
  c.probeInterval = 0.2;
  c.contactTimeout = 0.3;
  startClient(c);
  REQUIRE(waitContact());
  robot.reset();
  REQUIRE(runUntil(loop, [&] { return !lost.empty(); }));
  // On loopback the ICMP "port unreachable" usually comes first; either way it is named.
  const bool named = lost[0].find("udp 127.0.0.1:") != std::string::npos;
  CHECK(named);
  CHECK_FALSE(client->connected());
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: a robot that never answers fails the handshake with a clear reason") {
  MindroadServerOptions o;
  o.robot.ignoreContacts = 1000;
  startRobot(o);
  auto c = options();
  c.contactTimeout = 0.3;
  startClient(c);
  REQUIRE(runUntil(loop, [&] { return !lost.empty(); }));
  CHECK(lost[0].find("no contact answer (K) from tcp 127.0.0.1:") == 0);
  CHECK(lost[0].find("within 0.3 s") != std::string::npos);
  CHECK(contacts == 0);
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: nothing listening gives 'connection refused' once per outage") {
  startRobot();
  auto c = options();
  robot.reset();
  startClient(c);
  REQUIRE(runUntil(loop, [&] { return !lost.empty(); }));
  CHECK(lost[0].find("cannot connect to tcp 127.0.0.1:") == 0);
  CHECK(lost[0].find("refused") != std::string::npos);
  runFor(loop, std::chrono::milliseconds(700));
  CHECK(lost.size() == 1);
  CHECK(client->phase() == MindroadRobot::Phase::Waiting);
}

TEST_CASE_FIXTURE(Fixture,
                  "commands out of range are refused, naming the range, and send nothing") {
  startRobot();
  startClient(options());
  REQUIRE(waitContact());
  client->pauseKeepAlive(true);
  runFor(loop, std::chrono::milliseconds(50));
  const auto sent = client->instructionsSent();
  auto click = client->click(0, 60);
  REQUIRE_FALSE(click.ok());
  CHECK(click.error() == "click x 0 is out of range 1..160; nothing sent");
  CHECK(client->click(161, 60).error() == "click x 161 is out of range 1..160; nothing sent");
  CHECK(client->click(80, 121).error() == "click y 121 is out of range 1..120; nothing sent");
  CHECK(client->steer(128, 0).error() ==
        "steer x (forward/backward) 128 is out of range -128..127; nothing sent");
  CHECK(client->steer(0, -129).error() ==
        "steer y (right/left) -129 is out of range -128..127; nothing sent");
  CHECK(client->buttons(256).error() == "buttons byte 256 is out of range 0..255; nothing sent");
  CHECK(client->pictureMode("cmyk").error() ==
        "picture mode 'cmyk' is unknown; use rgb, hsv or filter; nothing sent");
  CHECK(client->instructionsSent() == sent);
  const auto received = state().instructions;
  runFor(loop, std::chrono::milliseconds(50));
  CHECK(state().instructions == received);
}

TEST_CASE_FIXTURE(Fixture,
                  "mindroad: closing the client stops the robot at once, not by its watchdog") {
  MindroadServerOptions o;
  o.robot.watchdog = 5;
  startRobot(o);
  startClient(options());
  REQUIRE(waitContact());
  REQUIRE(client->steer(100, 0));
  REQUIRE(runUntil(loop, [&] { return state().moving(); }));
  client->close();
  REQUIRE(runUntil(
      loop, [&] { return !state().moving(); }, std::chrono::seconds(2)));
  CHECK(state().lastStop == "stop instruction");
  CHECK(client->phase() == MindroadRobot::Phase::Closed);
  CHECK(client->steer(1, 0).error().find("is closed") != std::string::npos);
}
