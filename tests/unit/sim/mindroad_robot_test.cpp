// The simulated MindRoad robot's rules (mindroad.md "Behaviour"), without a network.
#include "engine/sim/mindroad_robot.hpp"

#include <doctest/doctest.h>

#include <vector>

using namespace pitwall;
using namespace pitwall::mindroad;
using pitwall::sim::MindroadRobot;

namespace {

std::vector<std::uint8_t> give(MindroadRobot& r, std::initializer_list<int> bytes, double t) {
  std::vector<std::uint8_t> b;
  for (int v : bytes) b.push_back(static_cast<std::uint8_t>(v));
  return r.receive(decode(b), t);
}

}  // namespace

TEST_CASE("mindroad: the robot answers contact, and only contact, with K") {
  MindroadRobot r;
  CHECK(give(r, {0x10}, 0) == std::vector<std::uint8_t>{0x4b});
  CHECK(r.state().contact);
  CHECK(give(r, {0x22, 0x7f, 0x00}, 0.1).empty());
  CHECK(give(r, {0x50}, 0.2).empty());
  CHECK(give(r, {0x00}, 0.3).empty());
}

TEST_CASE("mindroad: steering without contact is ignored; with contact it drives the body") {
  MindroadRobot r;
  give(r, {0x22, 0x7f, 0x00}, 0);
  CHECK_FALSE(r.state().moving());
  CHECK(r.state().ignored == 1);
  give(r, {0x10}, 0);
  give(r, {0x22, 0x7f, 0x00}, 0);
  CHECK(r.state().moving());
  r.advance(0.4);
  CHECK(r.state().x == doctest::Approx(0.2));  // 0.5 m/s for 0.4 s
  CHECK(r.state().y == doctest::Approx(0));
  give(r, {0x22, 0x00, 0x7f}, 0.4);  // full right on the spot: 90°/s clockwise
  r.advance(0.8);
  CHECK(r.state().heading == doctest::Approx(360 - 36));
  CHECK(r.state().x == doctest::Approx(0.2));
}

TEST_CASE(
    "mindroad: with no instruction within the watchdog period the robot stops and needs contact") {
  MindroadRobot r({.watchdog = 0.5});
  std::vector<std::string> events;
  r.onChange = [&](const std::string& e, const std::string&) { events.push_back(e); };
  give(r, {0x10}, 0);
  give(r, {0x22, 0x40, 0x00}, 0.1);
  give(r, {0x50}, 0.5);  // a ping holds contact
  r.advance(0.9);
  CHECK(r.state().moving());
  r.advance(1.01);
  CHECK_FALSE(r.state().moving());
  CHECK_FALSE(r.state().contact);
  CHECK(events.back() == "watchdog");
  give(r, {0x22, 0x40, 0x00}, 1.1);  // ignored until a new contact
  CHECK_FALSE(r.state().moving());
  give(r, {0x10}, 1.2);
  give(r, {0x22, 0x40, 0x00}, 1.2);
  CHECK(r.state().moving());
}

TEST_CASE(
    "mindroad: a malformed instruction stops the robot, and steering works again without contact") {
  MindroadRobot r;
  give(r, {0x10}, 0);
  give(r, {0x22, 0x7f, 0x00}, 0);
  give(r, {0x92, 0x01, 0x02}, 0.1);  // unused id 9
  CHECK_FALSE(r.state().moving());
  CHECK(r.state().contact);
  CHECK(r.state().malformed == 1);
  CHECK(r.state().lastStop.find("instruction 9 is unused") != std::string::npos);
  give(r, {0x22, 0x7f, 0x00}, 0.2);
  CHECK(r.state().moving());
  give(r, {0x21, 0x7f}, 0.3);  // steering with a wrong length
  CHECK_FALSE(r.state().moving());
  CHECK(r.state().malformed == 2);
}

TEST_CASE(
    "mindroad: stop and shutdown are obeyed; buttons, clicks and picture mode change the state") {
  MindroadRobot r;
  give(r, {0x10}, 0);
  give(r, {0x41, 0x01}, 0);
  CHECK(r.state().mode == "automatic");
  give(r, {0x41, 0x02}, 0);
  CHECK(r.state().sensitivity == 1);
  give(r, {0x32, 80, 60}, 0);
  CHECK(r.state().clickX == 80);
  give(r, {0x61, 0x02}, 0);
  CHECK(r.state().picture == Picture::Filter);
  give(r, {0x22, 0x7f, 0x00}, 0);
  give(r, {0x00}, 0.1);
  CHECK_FALSE(r.state().moving());
  CHECK(r.state().lastStop == "stop instruction");
  give(r, {0x70}, 0.2);
  CHECK(r.state().shutdown);
}

TEST_CASE("mindroad: a robot set to ignore the first contacts answers the next one") {
  MindroadRobot r({.ignoreContacts = 2});
  CHECK(give(r, {0x10}, 0).empty());
  CHECK(give(r, {0x10}, 0.1).empty());
  CHECK(give(r, {0x10}, 0.2) == std::vector<std::uint8_t>{0x4b});
  CHECK(r.state().ignored == 2);
}
