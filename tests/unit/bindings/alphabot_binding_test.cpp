// pitwall.alphabot{…} against the simulated robot over loopback, in a real-time Lua world: the
// object's shape, commands reaching the robot, events, bad input refused with nothing sent, the
// world's end closing the robot.
#include <doctest/doctest.h>

#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "engine/sim/alphabot_server.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
namespace simab = pitwall::sim::alphabot;

namespace {

struct AlphabotFixture {
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  simab::Robot robot{simab::defaultRoom()};
  simab::RobotServer server{loop, robot, "127.0.0.1", 0};
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;
  std::uint16_t portAtStart = server.port();

  AlphabotFixture() {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, HostOptions{});
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~AlphabotFixture() { log::setSink(nullptr); }

  // Runs code as a task with ROBOT_PORT set, until it sets DONE = true or an error is reported
  // (pitwall.stop() ends a host once; these tests run several chunks in one world). A 10 s
  // guard fails the run instead of hanging. Returns the error text, empty when it ran cleanly.
  std::string run(const std::string& code) {
    int before = host->errorCount();
    lua_pushnil(host->state());
    lua_setglobal(host->state(), "DONE");
    std::string prelude = "ROBOT_PORT = " + std::to_string(portAtStart) + "\n";
    auto started = host->startString(prelude + code, "test.lua");
    if (!started) return started.error();
    bool guardFired = false;
    auto deadline = loop.now() + std::chrono::seconds(10);
    std::function<void()> check = [&] {
      lua_getglobal(host->state(), "DONE");
      bool done = lua_toboolean(host->state(), -1);
      lua_pop(host->state(), 1);
      if (done || host->errorCount() > before) {
        loop.stop();
      } else if (loop.now() >= deadline) {
        guardFired = true;
        loop.stop();
      } else {
        loop.after(std::chrono::milliseconds(5), check);
      }
    };
    loop.post(check);
    loop.run();
    if (host->errorCount() > before) return logged.empty() ? "error" : logged.back();
    if (guardFired) return "guard: the script did not finish within 10 s";
    return "";
  }
  // Runs the loop until the simulated robot shows `done` (5 s at most).
  bool runUntilRobot(const std::function<bool()>& done) {
    return pitwall::testing::runUntil(loop, done);
  }
  std::string global(const char* name) {
    lua_getglobal(host->state(), name);
    std::string v = luaL_tolstring(host->state(), -1, nullptr);
    lua_pop(host->state(), 2);
    return v;
  }
};

constexpr const char* kConnect =
    "local r = pitwall.alphabot{host = '127.0.0.1', port = ROBOT_PORT}\n"
    "assert(pitwall.waitUntil(function() return r.connected end, 3), 'no connection')\n";

}  // namespace

TEST_CASE_FIXTURE(AlphabotFixture, "an alphabot object: name, fields, events and methods") {
  CHECK(run(std::string(kConnect) +
            "assert(tostring(r) == 'alphabot tcp:127.0.0.1:' .. ROBOT_PORT, tostring(r))\n"
            "assert(r.address == 'tcp:127.0.0.1:' .. ROBOT_PORT)\n"
            "assert(r.x == nil and r.heading == nil and r.lastError == nil)\n"
            "r.mine = 5; assert(r.mine == 5)\n"
            "assert(not pcall(function() r.onWhatever = print end))\n"
            "local ok, e = pcall(function() r.x = 1 end); assert(e:find('read%-only'), e)\n"
            "local ok2, e2 = pcall(function() r.drive = 1 end); assert(e2:find('method'), e2)\n"
            "assert(getmetatable(r).__name == 'alphabot')\n"
            "DONE = true") == "");
}

TEST_CASE_FIXTURE(
    AlphabotFixture,
    "a handler reads back as set; a closed robot refuses one, having no more events") {
  CHECK(run(std::string(kConnect) +
            "local f = function() end\n"
            "r.onPing = f; assert(r.onPing == f)\n"
            "r:close()\n"
            "local ok, e = pcall(function() r.onPing = print end)\n"
            "assert(not ok and e:find('alphabot tcp:127.0.0.1:' .. ROBOT_PORT .. "
            "' is closed: it has no more events', 1, true), e)\n"
            "r.onPing = nil; assert(r.onPing == nil)\n"
            "local ok2, e2 = pcall(function() r.onPing = 42 end)\n"
            "assert(e2:find('must be a function or nil'), e2)\n"
            "DONE = true") == "");
}

TEST_CASE_FIXTURE(AlphabotFixture, "every command reaches the robot and every answer is an event") {
  REQUIRE(run(std::string(kConnect) +
              "local got = {}\n"
              "r.onDistance = function(rb, ev) assert(rb == r); got[#got+1] = ev.degree .. '=' .. "
              "ev.distance end\n"
              "r.onCompass = function(_, ev) compass = ev.degree end\n"
              "r.onPing = function(_, ev) rtt = ev.rtt end\n"
              "r.onObstacle = function(_, ev) obstacle = ev.id .. ':' .. ev.x .. ',' .. ev.y .. ' "
              "' .. ev.width .. 'x' .. ev.height end\n"
              "r.onPath = function(_, ev) waypoints = #ev.waypoints; last = "
              "ev.waypoints[#ev.waypoints] end\n"
              "r.onPosition = function(_, ev) positions = (positions or 0) + 1 end\n"
              "r:measureDistance(0); r:measureDistance(90); r:measureDistance(180)\n"
              "r:calibrateCompass(); r:ping(); r:calibrateSteering()\n"
              "r:addObstacle(180, 100, 40, 100)\n"
              "r:setAnchor(4, 400, 300)\n"
              "r:set{positioning = true, logCompass = true}\n"
              "assert(r.toggles.positioning and r.toggles.logCompass and not r.toggles.invite)\n"
              "r:navigateTo(120, 220)\n"
              "assert(pitwall.waitUntil(function() return r.x == 120 and r.y == 220 end, 8), 'not "
              "there')\n"
              "distances = table.concat(got, ' ')\n"
              "r:removeObstacle(1); r:removeObstacle(10, 10); r:clearObstacles()\n"
              "r:drive(20, 0); r:drive(0, 0)\n"
              "DONE = true") == "");
  CHECK(global("distances") == "0=130 90=150 180=50");
  CHECK(global("obstacle") == "1:180,100 40x100");
  CHECK(global("compass") != "nil");
  CHECK(std::stod(global("rtt")) >= 0);
  CHECK(global("waypoints") == "1");  // nothing in the way: one straight leg
  CHECK(std::stoi(global("positions")) >= 3);
  // 3 distances, compass, ping, steering, obstacle, anchor, toggles, navigate, 3 removals, 2 drives
  CHECK(runUntilRobot([&] { return server.requests() == 15; }));
  CHECK(robot.map().empty());
}

TEST_CASE_FIXTURE(AlphabotFixture, "bad input raises an error naming the range and sends nothing") {
  std::string code =
      std::string(kConnect) +
      "local function err(f, ...) local ok, e = pcall(f, r, ...); assert(not ok); return e end\n"
      "e1 = err(r.drive, 200, 0)\n"
      "e2 = err(r.drive, 0, -129)\n"
      "e3 = err(r.drive, 128.5, 0)\n"
      "e4 = err(r.set, {warpDrive = true})\n"
      "e5 = err(r.set, {positioning = 1})\n"
      "e6 = err(r.addObstacle, 1, 2, 0, 4)\n"
      "e7 = err(r.navigateTo, 40000, 0)\n"
      "e8 = err(r.measureDistance, 720)\n"
      "e9 = err(r.setAnchor, 256, 0, 0)\n"
      "DONE = true";
  REQUIRE(run(code) == "");
  CHECK(global("e1").find("speed 200 is out of range -128..127") != std::string::npos);
  CHECK(global("e2").find("steer -129 is out of range -128..127") != std::string::npos);
  // a computed value is rounded half away from zero, then range-checked: 128.5 → 129
  CHECK(global("e3").find("speed 129 is out of range -128..127") != std::string::npos);
  INFO(global("e4"));
  CHECK(global("e4").find("set: unknown option warpDrive (the options are compassCalibration, "
                          "invite") != std::string::npos);
  CHECK(global("e5").find("must be true or false") != std::string::npos);
  CHECK(global("e6").find("width (cm) 0 is out of range 1..65535") != std::string::npos);
  CHECK(global("e7").find("x (cm) 40000 is out of range -32768..32767") != std::string::npos);
  CHECK(global("e8").find("degree 720 is out of range -360..360") != std::string::npos);
  CHECK(global("e9").find("anchor id 256 is out of range 0..255") != std::string::npos);
  CHECK(server.requests() == 0);
  CHECK(robot.toggles() == alphabot::Toggles{});
}

TEST_CASE_FIXTURE(AlphabotFixture, "constructor options are checked") {
  auto err = [&](const std::string& code) {
    return run("local ok, e = pcall(pitwall.alphabot, " + code +
               "); assert(not ok); E = e; DONE = true") == ""
               ? global("E")
               : std::string("ran");
  };
  CHECK(err("'x'").find("takes a table") != std::string::npos);
  CHECK(err("{}").find("needs either host") != std::string::npos);
  CHECK(err("{host = '127.0.0.1'}").find("needs a port") != std::string::npos);
  CHECK(err("{host = '127.0.0.1', port = 70000}").find("port 70000 is out of range 1..65535") !=
        std::string::npos);
  CHECK(err("{host = 'h', port = 1, colour = 'red'}").find("unknown option colour (the options") !=
        std::string::npos);
  CHECK(err("{hots = 'h', port = 1}")
            .find("pitwall.alphabot: unknown option hots; did you mean "
                  "host?") != std::string::npos);
}

TEST_CASE_FIXTURE(AlphabotFixture,
                  "a robot that goes away: onDisconnect, commands refused, back with onConnect") {
  std::uint16_t port = server.port();
  REQUIRE(run(std::string(kConnect) +
              "robot = r\n"
              "r.onDisconnect = function(_, ev) reason = ev.reason end\n"
              "r.onConnect = function() connects = (connects or 0) + 1 end\n"
              "DONE = true") == "");
  server.close();  // the robot disappears
  REQUIRE(
      run("assert(pitwall.waitUntil(function() return reason ~= nil end, 3), 'no onDisconnect')\n"
          "assert(not robot.connected)\n"
          "local ok, e = pcall(robot.drive, robot, 10, 0)\n"
          "refused = e\n"
          "DONE = true") == "");
  CHECK(global("reason") == "the robot closed the connection");
  CHECK(global("refused").find("nothing sent: tcp:127.0.0.1:" + std::to_string(port) +
                               ": not connected") != std::string::npos);
  simab::RobotServer again(loop, robot, "127.0.0.1", port);  // it is back
  REQUIRE(run("assert(pitwall.waitUntil(function() return connects == 1 end, 5), 'no onConnect')\n"
              "robot:ping()\n"
              "assert(pitwall.waitUntil(function() return robot.lastPing ~= nil end, 3))\n"
              "DONE = true") == "");
  CHECK(again.requests() == 1);
}

TEST_CASE_FIXTURE(AlphabotFixture, "ping() in a task returns the round-trip time") {
  REQUIRE(run(std::string(kConnect) +
              "local rtt = r:ping()\n"
              "assert(type(rtt) == 'number' and rtt >= 0 and rtt < 1, tostring(rtt))\n"
              "assert(rtt == r.lastPing and r.pings == 1)\n"
              "-- in a callback it only sends: the time arrives in onPing\n"
              "r.onPing = function(_, ev) viaEvent = ev.rtt end\n"
              "pitwall.after(0, function() fromCallback = r:ping() end)\n"
              "assert(pitwall.waitUntil(function() return viaEvent ~= nil end, 3), 'no onPing')\n"
              "assert(fromCallback == nil and r.pings == 2)\n"
              "DONE = true") == "");
}

TEST_CASE_FIXTURE(AlphabotFixture, "the end of the Lua world stops and closes its robots") {
  REQUIRE(run(std::string(kConnect) + "r:drive(40, 0)\nDONE = true") == "");
  REQUIRE(runUntilRobot([&] { return robot.moving(); }));
  host.reset();  // end of run / hot reload: the world goes
  REQUIRE(runUntilRobot([&] { return !robot.moving() && server.clients() == 0; }));
  CHECK(!robot.bumped());  // stopped by the stop it was sent, not by the box ahead
}

TEST_CASE("pitwall.alphabot{host=…} refuses a virtual clock, saying why") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  ScriptHost host(loop, fleet, nullptr, HostOptions{});
  std::vector<std::string> logged;
  log::setSink([&](log::Level, std::string_view line) { logged.emplace_back(line); });
  REQUIRE(host.startString("pitwall.alphabot{host = '127.0.0.1', port = 1}", "v.lua"));
  loop.run();
  log::setSink(nullptr);
  REQUIRE(!logged.empty());
  CHECK(logged.back().find("needs the real clock: run without --fast") != std::string::npos);
}

TEST_CASE_FIXTURE(AlphabotFixture, "ready when made: in a task the next line can drive") {
  REQUIRE(run("local r = pitwall.alphabot{host = '127.0.0.1', port = ROBOT_PORT}\n"
              "r:drive(40, 0)\n"
              "DONE = true") == "");
  REQUIRE(runUntilRobot([&] { return robot.moving(); }));
}

TEST_CASE_FIXTURE(AlphabotFixture,
                  "an unreachable robot gives a clear error after connectTimeout") {
  std::uint16_t port = server.port();
  server.close();  // nothing listens there now
  REQUIRE(run("local ok, e = pcall(pitwall.alphabot, {host = '127.0.0.1', port = ROBOT_PORT, "
              "connectTimeout = 0.3})\n"
              "E = e; DONE = true") == "");
  const std::string p = std::to_string(port);
  CHECK(global("E").find("alphabot tcp:127.0.0.1:" + p +
                         " is not connected after 0.3 s (connectTimeout): ") != std::string::npos);
  CHECK(global("E").find("refused") != std::string::npos);
}

TEST_CASE_FIXTURE(AlphabotFixture, "in a callback pitwall.alphabot returns at once") {
  REQUIRE(run("pitwall.after(0, function()\n"
              "  local r = pitwall.alphabot{host = '127.0.0.1', port = ROBOT_PORT}\n"
              "  AT_ONCE = r.connected\n"
              "  DONE = true\n"
              "end)") == "");
  CHECK(global("AT_ONCE") == "false");
}

TEST_CASE_FIXTURE(AlphabotFixture,
                  "pitwall.listen follows an alphabot's events, before its handler, as a car's") {
  REQUIRE(
      run(std::string(kConnect) +
          "local order = {}\n"
          "local sub = pitwall.listen(r, 'onPing', function(robot, ev)\n"
          "  assert(robot == r and type(ev.rtt) == 'number')\n"
          "  order[#order + 1] = 'listener'\n"
          "end)\n"
          "r.onPing = function() order[#order + 1] = 'handler' end\n"
          "r:ping()\n"
          "assert(table.concat(order, ',') == 'listener,handler', table.concat(order, ','))\n"
          "assert(sub:cancel())\n"
          "r:ping()\n"
          "assert(table.concat(order, ',') == 'listener,handler,handler')\n"
          "local ok, e = pcall(pitwall.listen, r, 'onPong', print)\n"
          "assert(not ok and e:find(\"cannot listen to 'onPong'; the events are onDistance\"), e)\n"
          "r:close()\n"
          "ok, e = pcall(pitwall.listen, r, 'onPing', print)\n"
          "assert(not ok and e:find('is closed: it has no more events'), e)\n"
          "DONE = true") == "");
}
