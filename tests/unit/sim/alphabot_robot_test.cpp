// The simulated Alphabot as a model: requests in, responses out, time stepped by hand.
#include "engine/sim/alphabot_robot.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "engine/protocol/alphabot/toggles.hpp"

using namespace pitwall::sim::alphabot;
namespace ab = pitwall::alphabot;

namespace {

struct Fixture {
  Robot robot{defaultRoom()};
  std::vector<ab::Response> out;
  Fixture() {
    robot.emit = [this](const ab::Response& r) { out.push_back(r); };
  }
  template <class T>
  std::vector<T> all() const {
    std::vector<T> v;
    for (const auto& r : out)
      if (auto* m = std::get_if<T>(&r)) v.push_back(*m);
    return v;
  }
  void run(double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / 0.02)); ++i) robot.step(0.02);
  }
  ab::Toggles toggles(std::initializer_list<const char*> names) {
    ab::Toggles t;
    for (auto* n : names) ab::setBit(t, *ab::findToggle(n), true);
    return t;
  }
};

}  // namespace

TEST_CASE("the distance sensor sees walls and obstacles at the requested degree") {
  Fixture f;  // at (50, 150) facing +x; box x 180..220, y 100..200; room 400 × 300
  for (int degree : {0, 90, 180, -90, 45})
    f.robot.receive(ab::MeasureDistance{static_cast<std::int16_t>(degree)});
  auto d = f.all<ab::Distance>();
  REQUIRE(d.size() == 5);
  CHECK(d[0] == ab::Distance{0, 130});    // the box
  CHECK(d[1] == ab::Distance{90, 150});   // the far wall (y = 300)
  CHECK(d[2] == ab::Distance{180, 50});   // the wall behind (x = 0)
  CHECK(d[3] == ab::Distance{-90, 150});  // the near wall (y = 0)
  CHECK(d[4] == ab::Distance{45, 212});   // the wall y = 300 at 45°: 150 × √2
}

TEST_CASE("ping is echoed, calibrate-compass reports the heading, toggles turn on reports") {
  Fixture f;
  f.robot.receive(ab::Ping{987654321});
  f.robot.receive(ab::CalibrateCompass{});
  CHECK(f.all<ab::PingReply>() == std::vector<ab::PingReply>{{987654321}});
  CHECK(f.all<ab::Compass>() == std::vector<ab::Compass>{{0}});
  f.out.clear();
  f.robot.receive(ab::SetToggles{f.toggles({"positioning", "logCompass", "logObstacleDistance"})});
  CHECK(f.all<ab::Position>().size() == 1);  // at once when positioning turns on
  f.run(1.1);
  CHECK(f.all<ab::Position>().size() >= 4);
  CHECK(f.all<ab::Compass>().size() >= 4);
  CHECK(f.all<ab::Distance>().size() >= 4);
  f.out.clear();
  f.robot.receive(ab::SetAnchor{4, 400, 300});
  CHECK(f.all<ab::Position>() == std::vector<ab::Position>{{50, 150}});
}

TEST_CASE("obstacles get ids when registered and leave the map by id, by position or all") {
  Fixture f;
  f.robot.receive(ab::AddObstacle{10, 20, 30, 40});
  f.robot.receive(ab::AddObstacle{100, 100, 10, 10});
  f.robot.receive(ab::AddObstacle{200, 200, 10, 10});
  auto reg = f.all<ab::ObstacleRegistered>();
  REQUIRE(reg.size() == 3);
  CHECK(reg[0] == ab::ObstacleRegistered{1, 10, 20, 30, 40});
  CHECK(reg[1].id == 2);
  CHECK(reg[2].id == 3);
  f.robot.receive(ab::RemoveObstacleById{2});
  CHECK(f.robot.map().size() == 2);
  f.robot.receive(ab::RemoveObstacleAt{205, 205});
  REQUIRE(f.robot.map().size() == 1);
  CHECK(f.robot.map()[0].id == 1);
  f.robot.receive(ab::ClearObstacles{});
  CHECK(f.robot.map().empty());
}

TEST_CASE("navigation reports a path around the mapped obstacles and drives it to the target") {
  Fixture f;
  f.robot.receive(ab::AddObstacle{180, 100, 40, 100});
  f.robot.receive(ab::NavigateTo{350, 150});
  auto paths = f.all<ab::Path>();
  REQUIRE(paths.size() == 1);
  const auto& w = paths[0].waypoints;
  REQUIRE(w.size() >= 2);  // not straight through the box
  CHECK(w.back() == ab::Waypoint{350, 150});
  f.run(30);
  CHECK(!f.robot.navigating());
  CHECK(std::abs(f.robot.x() - 350) < 1);
  CHECK(std::abs(f.robot.y() - 150) < 1);
  CHECK(!f.robot.bumped());
  CHECK(f.all<ab::Position>().back() == ab::Position{350, 150});
}

TEST_CASE("an unreachable target gives an empty path and the robot stays") {
  Fixture f;
  f.robot.receive(ab::AddObstacle{300, 0, 20, 300});  // a wall across the room
  f.robot.receive(ab::NavigateTo{370, 150});
  REQUIRE(f.all<ab::Path>().size() == 1);
  CHECK(f.all<ab::Path>()[0].waypoints.empty());
  f.robot.receive(ab::NavigateTo{500, 150});  // outside the room
  CHECK(f.all<ab::Path>()[1].waypoints.empty());
  f.run(1);
  CHECK(f.robot.x() == 50);
}

TEST_CASE("collision avoidance stops the robot short of the obstacle; without it, it bumps") {
  Fixture with;
  with.robot.receive(ab::SetToggles{with.toggles({"collisionAvoidance"})});
  with.robot.receive(ab::Drive{100, 0});
  with.run(10);
  CHECK(!with.robot.moving());
  CHECK(with.robot.avoided());
  CHECK(with.robot.x() + 10 < 180 - 3);  // the edge stays a few cm off the box

  Fixture without;
  without.robot.receive(ab::Drive{100, 0});
  without.run(10);
  CHECK(!without.robot.moving());
  CHECK(without.robot.bumped());
  CHECK(without.robot.x() + 10 > 180 - 1.5);  // at the box
}

TEST_CASE("drive turns by steer: negative steer turns left (counter-clockwise)") {
  Fixture f;
  f.robot.receive(ab::Drive{0, -90});
  f.run(1.0);
  CHECK(std::abs(f.robot.heading() - 90) < 2);
}

TEST_CASE("room files: statements, defaults and errors naming the line") {
  auto room = parseRoom(
      "# a room\nroom 200 100\nrobot 20 50 90\nobstacle 100 0 10 50\nanchor 1 0 0\n", "r.txt");
  REQUIRE(room.ok());
  CHECK(room->width == 200);
  CHECK(room->startHeading == 90);
  CHECK(room->obstacles.size() == 1);
  CHECK(room->anchors.size() == 1);
  CHECK(parseRoom("room 200\n", "r.txt").error() ==
        "r.txt:1: room takes WIDTH HEIGHT, got 1 number(s)");
  CHECK(parseRoom("room 200 100\nwall 1 2\n", "r.txt")
            .error()
            .find("r.txt:2: unknown statement 'wall'") == 0);
  CHECK(parseRoom("obstacle 1 2 x 4\n", "r.txt").error() == "r.txt:1: 'x' is not a number");
  CHECK(parseRoom("room 200 100\nrobot 300 50\n", "r.txt").error().find("outside the room") !=
        std::string::npos);
  CHECK(parseRoom("robot 50 50\nobstacle 40 40 20 20\n", "r.txt")
            .error()
            .find("inside an obstacle") != std::string::npos);
}
