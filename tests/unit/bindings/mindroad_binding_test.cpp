// pitwall.mindroad from Lua against the simulated robot over loopback: the object, its events,
// errors naming the range with nothing sent, the REPL's shutdown confirmation, and the link's
// end with the Lua world that made it.
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/core/console.hpp"
#include "engine/core/log.hpp"
#include "engine/sim/mindroad_robot_server.hpp"
#include "tests/support/run_until.hpp"

using namespace pitwall;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;

namespace {

struct RobotLua {
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  std::unique_ptr<sim::MindroadRobotServer> robot;
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;
  std::string printed;

  RobotLua() {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
    console::setWriter([this](std::string_view text) { printed += text; });
    startRobot(0);
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, HostOptions{});
  }
  ~RobotLua() {
    host.reset();
    robot.reset();
    console::setWriter(nullptr);
    log::setSink(nullptr);
  }
  void startRobot(std::uint16_t port) {
    sim::MindroadServerOptions o;
    o.port = port;
    robot = std::make_unique<sim::MindroadRobotServer>(loop, o);
  }
  std::string port() { return std::to_string(robot->port()); }
  // Starts code as a task (the robot's port in the global PORT).
  void start(const std::string& code) {
    lua_pushinteger(host->state(), robot->port());
    lua_setglobal(host->state(), "PORT");
    auto started = host->startString(code, "test.lua");
    REQUIRE_MESSAGE(started.ok(), (started.ok() ? "" : started.error()));
  }
  bool global(const char* name) {
    lua_getglobal(host->state(), name);
    bool v = lua_toboolean(host->state(), -1);
    lua_pop(host->state(), 1);
    return v;
  }
  std::string string(const char* name) {
    lua_getglobal(host->state(), name);
    const char* s = lua_tostring(host->state(), -1);
    std::string v = s ? s : "";
    lua_pop(host->state(), 1);
    return v;
  }
  bool waitFor(const char* name, Duration limit = std::chrono::seconds(5)) {
    return runUntil(
        loop, [&] { return global(name); }, limit);
  }
  const sim::MindroadRobotState& state() { return robot->robot().state(); }
};

}  // namespace

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: pitwall.mindroad makes a robot object that shakes hands and steers") {
  start(R"(
    robot = pitwall.mindroad{host = "127.0.0.1", port = PORT}
    name = getmetatable(robot).__name
    label = tostring(robot)  -- ready when made: in contact already
    contacted = robot.connected
    robot:steer(127, 0)
    robot:click(80, 60)
    robot:buttons("automatic")
    robot:pictureMode("hsv")
    robot.laps = 3  -- the script's own field
    fields = robot.host == "127.0.0.1" and robot.port == PORT and robot.udp == false
      and robot.watchdog == 0.5 and robot.phase == "contact" and robot.laps == 3
    done = true
  )");
  REQUIRE(waitFor("done"));
  CHECK(string("name") == "mindroad");
  CHECK(string("label") == "mindroad tcp 127.0.0.1:" + port() + " (contact)");
  CHECK(global("contacted"));
  CHECK(global("fields"));
  REQUIRE(runUntil(loop, [&] { return state().picture == mindroad::Picture::Hsv; }));
  CHECK(state().steerX == 127);
  CHECK(state().clickX == 80);
  CHECK(state().mode == "automatic");
}

TEST_CASE_FIXTURE(RobotLua,
                  "bad input from Lua raises an error naming the range; nothing is sent") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    pitwall.waitUntil(function() return robot.connected end, 3)
    local function try(f) local ok, e = pcall(f); return e end
    clickError = try(function() robot:click(0, 60) end)
    steerError = try(function() robot:steer(0, 300) end)
    modeError = try(function() robot:pictureMode("cmyk") end)
    buttonError = try(function() robot:buttons("turbo") end)
    typeError = try(function() robot:steer("fast", 0) end)
    eventError = try(function() robot.onCrash = print end)
    fieldError = try(function() robot.connected = true end)
    optionError = try(function() pitwall.mindroad{prot = 4000} end)
    portError = try(function() pitwall.mindroad{port = 70000} end)
    done = true
  )");
  REQUIRE(waitFor("done"));
  CHECK(string("clickError") == "test.lua:5: click x 0 is out of range 1..160; nothing sent");
  CHECK(string("steerError") ==
        "test.lua:6: steer y (right/left) 300 is out of range -128..127; nothing sent");
  CHECK(string("modeError") ==
        "test.lua:7: picture mode 'cmyk' is unknown; use rgb, hsv or filter; nothing sent");
  CHECK(string("buttonError") ==
        "test.lua:8: button 'turbo' is unknown (use manual, automatic, sensitivity-up or "
        "sensitivity-down)");
  CHECK(string("typeError") ==
        "test.lua:9: steer x (forward/backward) must be a number, "
        "got string");
  CHECK(string("eventError") ==
        "test.lua:10: robot.onCrash is not an event; the events are onContact, onLost");
  CHECK(string("fieldError") ==
        "test.lua:11: robot.connected is read-only (it is the robot's state)");
  CHECK(string("optionError") ==
        "test.lua:12: pitwall.mindroad: unknown option prot; did you mean port? (the options are "
        "host, port, udp, watchdog, contactTimeout)");
  CHECK(string("portError") == "test.lua:13: port 70000 is out of range 1..65535");
  runFor(loop, std::chrono::milliseconds(50));
  CHECK(state().clickX == 0);  // no click arrived
  CHECK(state().steerX == 0);
  CHECK(state().malformed == 0);
}

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: a robot that disappears reaches onLost; when it is back, onContact") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    contacts = 0
    -- the first contact came while pitwall.mindroad waited: onContact hears the next one
    robot.onContact = function() contacts = contacts + 1; contactedAgain = contacts >= 1 end
    robot.onLost = function(r, reason) lostReason = reason; gone = true end
    pitwall.waitUntil(function() return robot.connected end, 3)
    up = true
    pitwall.waitUntil(function() return gone end, 5)
    steerError = select(2, pcall(robot.steer, robot, 10, 0))
  )");
  REQUIRE(waitFor("up"));
  const auto port = robot->port();
  robot.reset();
  REQUIRE(waitFor("gone"));
  CHECK(string("lostReason") == "tcp 127.0.0.1:" + std::to_string(port) + " closed the connection");
  REQUIRE(runUntil(loop, [&] { return !string("steerError").empty(); }));
  CHECK(string("steerError").find("has no contact (reconnecting: tcp 127.0.0.1:") !=
        std::string::npos);
  startRobot(port);
  REQUIRE(waitFor("contactedAgain", std::chrono::seconds(6)));
}

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: an error in onLost is reported naming the handler; the run goes on") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    robot.onLost = function() error("boom") end
    pitwall.waitUntil(function() return robot.connected end, 3)
    up = true
  )");
  REQUIRE(waitFor("up"));
  robot.reset();
  REQUIRE(runUntil(loop, [&] { return host->errorCount() > 0; }));
  bool named = false;
  for (const auto& l : logged)
    if (l.find("onLost handler of mindroad tcp 127.0.0.1:") != std::string::npos &&
        l.find("boom") != std::string::npos)
      named = true;
  CHECK(named);
}

TEST_CASE_FIXTURE(RobotLua,
                  "the connection ends with the Lua world that made it; the robot stops") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    pitwall.waitUntil(function() return robot.connected end, 3)
    robot:steer(100, 0)
    robot = nil  -- even unreferenced, the robot is kept until its world ends
    collectgarbage()
    up = true
  )");
  REQUIRE(waitFor("up"));
  REQUIRE(runUntil(loop, [&] { return state().moving(); }));
  runFor(loop, std::chrono::milliseconds(300));  // past the watchdog: pings still go out
  CHECK(state().moving());
  host.reset();  // end of the run, or a hot reload replacing this world
  REQUIRE(runUntil(loop, [&] { return !state().moving(); }));
  CHECK(state().lastStop == "stop instruction");
  REQUIRE(runUntil(loop, [&] { return robot->connections() == 0; }));
}

TEST_CASE_FIXTURE(RobotLua,
                  "shutdown at the REPL asks first: only a second call within 5 s sends") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    pitwall.waitUntil(function() return robot.connected end, 3)
    up = true
  )");
  REQUIRE(waitFor("up"));
  auto typed = [&](const std::string& line) {
    lua_State* L = host->state();
    REQUIRE(luaL_loadbuffer(L, line.data(), line.size(), "=stdin") == LUA_OK);
    std::string error;
    REQUIRE_MESSAGE(host->callInteractive(0, 1, error), error);
    bool sent = lua_toboolean(L, -1);
    lua_pop(L, 1);
    return sent;
  };
  CHECK_FALSE(typed("return robot:shutdown()"));
  CHECK(printed.find("shutdown() turns the robot OFF") != std::string::npos);
  runFor(loop, std::chrono::milliseconds(50));
  CHECK_FALSE(state().shutdown);
  CHECK(typed("return robot:shutdown()"));
  REQUIRE(runUntil(loop, [&] { return state().shutdown; }));
}

TEST_CASE_FIXTURE(RobotLua, "mindroad: shutdown from a script is sent at once") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    pitwall.waitUntil(function() return robot.connected end, 3)
    robot.onLost = function(r, reason) lostReason = reason end
    sent = robot:shutdown()
  )");
  REQUIRE(waitFor("sent"));
  REQUIRE(runUntil(loop, [&] { return state().shutdown; }));
  CHECK(printed.find("turns the robot OFF") == std::string::npos);
  robot->close();  // the robot turns off
  REQUIRE(runUntil(loop, [&] { return !string("lostReason").empty(); }));
  CHECK(string("lostReason").find("(after shutdown: not reconnecting)") != std::string::npos);
  lua_getglobal(host->state(), "robot");
  lua_getfield(host->state(), -1, "phase");
  CHECK(std::string(lua_tostring(host->state(), -1)) == "closed");
  lua_pop(host->state(), 2);
}

TEST_CASE_FIXTURE(RobotLua, "mindroad: a closed robot refuses commands and says so") {
  start(R"(
    robot = pitwall.mindroad{port = PORT}
    pitwall.waitUntil(function() return robot.connected end, 3)
    robot:close()
    label = tostring(robot)
    closedError = select(2, pcall(robot.steer, robot, 1, 1))
    done = true
  )");
  REQUIRE(waitFor("done"));
  CHECK(string("label") == "mindroad tcp 127.0.0.1:" + port() + " (closed)");
  // (called through pcall: the error names the line that called pcall)
  CHECK(string("closedError") ==
        "test.lua:6: mindroad tcp 127.0.0.1:" + port() + " is closed; nothing sent");
}

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: a robot met again after its finalizer is refused, not read") {
  // Lua 5.4 keeps a finalized object as a weak table's key until the next collection: a script
  // can reach it after its box was emptied. It must be refused like any wrong value.
  start(R"(
    seen = setmetatable({}, {__mode = "k"})
    do
      local robot = pitwall.mindroad{port = PORT}
      robot:close()
      seen[robot] = true
    end
    collectgarbage()
    for robot in pairs(seen) do
      met = true
      readOk, readError = pcall(function() return robot.connected end)
      label = tostring(robot)
    end
    done = true
  )");
  REQUIRE(waitFor("done"));
  REQUIRE(global("met"));
  CHECK_FALSE(global("readOk"));
  CHECK(string("readError").find("attempt to index a userdata value") != std::string::npos);
  CHECK(string("label").rfind("userdata: ", 0) == 0);  // a plain userdata, its label not read
}

TEST_CASE_FIXTURE(RobotLua, "mindroad: ready when made: in a task the next line can steer") {
  start(R"(
    robot = pitwall.mindroad{host = "127.0.0.1", port = PORT}
    robot:steer(100, 0)
    done = true
  )");
  REQUIRE(waitFor("done"));
  REQUIRE(runUntil(loop, [&] { return state().steerX == 100; }));
}

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: an unreachable robot gives a clear error after contactTimeout") {
  const auto port = robot->port();
  robot.reset();  // nothing listens there now
  lua_pushinteger(host->state(), port);
  lua_setglobal(host->state(), "UNREACHABLE");
  startRobot(0);  // another robot, elsewhere
  start(R"(
    local ok, e = pcall(pitwall.mindroad, {port = UNREACHABLE, contactTimeout = 0.3})
    failure = e
    done = true
  )");
  REQUIRE(waitFor("done"));
  const std::string p = std::to_string(port);
  CHECK(string("failure").find("mindroad tcp 127.0.0.1:" + p + " has no contact after 0.3 s " +
                               "(contactTimeout): cannot connect to tcp 127.0.0.1:" + p) !=
        std::string::npos);
  CHECK(string("failure").find("refused") != std::string::npos);
}

TEST_CASE_FIXTURE(RobotLua, "mindroad: in a callback pitwall.mindroad returns at once") {
  start(R"(
    pitwall.after(0, function()
      robot = pitwall.mindroad{port = PORT}
      phaseAtOnce = robot.phase
      done = true
    end)
  )");
  REQUIRE(waitFor("done"));
  CHECK(string("phaseAtOnce") == "connecting");
}

TEST_CASE_FIXTURE(RobotLua,
                  "mindroad: pitwall.listen follows a robot's events before its handler") {
  start(R"(
    order = {}
    pitwall.after(0, function()  -- in a callback: the robot is returned before its first contact
      robot = pitwall.mindroad{port = PORT}
      sub = pitwall.listen(robot, "onContact", function(r) order[#order + 1] = "listener" end)
      robot.onContact = function(r)
        order[#order + 1] = "handler"
        contact = true
      end
    end)
  )");
  REQUIRE(waitFor("contact"));
  start(R"(
    result = table.concat(order, ",")
    cancelled = sub:cancel()
    robot:close()
    local ok, e = pcall(pitwall.listen, robot, "onLost", print)
    refused = e
  )");
  CHECK(string("result") == "listener,handler");
  CHECK(global("cancelled"));
  CHECK(string("refused").find("is closed: it has no more events") != std::string::npos);
}
