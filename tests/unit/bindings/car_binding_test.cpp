// The Lua surface of cars, driven through a CaptureLink (no simulator): what scripts see and what
// reaches the car.
#include "bindings/car_binding.hpp"

#include <doctest/doctest.h>

#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "tests/unit/capture_link.hpp"

using namespace pitwall;
using namespace pitwall::anki;
using pitwall::testing::CaptureLink;

namespace {

struct LuaFixture {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  CaptureLink* link = nullptr;
  AnkiCar* car = nullptr;
  std::unique_ptr<ScriptHost> host;
  std::vector<std::string> logged;

  LuaFixture() {
    auto l = std::make_unique<CaptureLink>();
    link = l.get();
    car = &fleet.add(std::move(l), CarIdentity{0, "skull", 9, 1});
    link->setConnected(true);
    link->sent.clear();
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, HostOptions{});
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~LuaFixture() { log::setSink(nullptr); }

  // Runs code as a task; returns the error text, empty when it ran cleanly.
  std::string run(const std::string& code) {
    int before = host->errorCount();
    auto started = host->startString(code, "test.lua");
    if (!started) return started.error();
    loop.run();
    if (host->errorCount() > before) return logged.empty() ? "error" : logged.back();
    return "";
  }
  double number(const char* global) {
    lua_getglobal(host->state(), global);
    double v = lua_tonumber(host->state(), -1);
    lua_pop(host->state(), 1);
    return v;
  }
};

}  // namespace

TEST_CASE_FIXTURE(LuaFixture, "a car is one Lua value: the same object every time") {
  CHECK(run("local a = pitwall.cars()[1]; local b = pitwall.car('skull'); "
            "assert(a == b and rawequal(a, b)); assert(tostring(a) == 'car 1 (skull)')") == "");
}

TEST_CASE_FIXTURE(LuaFixture, "setSpeed from Lua sends the frame the codec makes") {
  CHECK(run("pitwall.cars()[1]:setSpeed(1000, 25000)") == "");
  REQUIRE(link->sent.size() == 1);
  CHECK(link->sent[0] == std::vector<std::uint8_t>{0x06, 0x24, 0xe8, 0x03, 0xa8, 0x61, 0x00});
}

TEST_CASE_FIXTURE(LuaFixture,
                  "an out-of-range command raises an error naming the range, sends nothing") {
  std::string err = run("pitwall.cars()[1]:setSpeed(5000)");
  CHECK(err.find("test.lua:1:") != std::string::npos);
  CHECK(err.find("0..1500") != std::string::npos);
  CHECK(link->sent.empty());
  CHECK(
      run("pitwall.cars()[1]:setSpeed('fast')").find("speed (mm/s) must be a number, got string") !=
      std::string::npos);
  CHECK(run("pitwall.cars()[1]:turn('sideways')").find("left, right, uturn") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "onPosition receives the car and an event with the reported fields") {
  REQUIRE(run("local car = pitwall.cars()[1]\n"
              "car.onPosition = function(c, ev) got_piece, got_loc, got_speed, got_off, got_time ="
              " ev.piece, ev.location, ev.speed, ev.offset, ev.time; same = (c == car) end") == "");
  loop.after(std::chrono::seconds(2), [&] {
    PositionUpdate p;
    p.piece_id = 17;
    p.location_id = 9;
    p.speed_mm_s = 640;
    p.offset_mm = 23.0f;
    link->carSends(p);
  });
  loop.run();
  CHECK(number("got_piece") == 17);
  CHECK(number("got_loc") == 9);
  CHECK(number("got_speed") == 640);
  CHECK(number("got_off") == 23.0);
  CHECK(number("got_time") == 2.0);
  CHECK(run("assert(same == true); assert(pitwall.cars()[1].piece == 17)") == "");
}

// anki-overdrive.md **Decision**: frames longer than their layout are read, and what they carry
// beyond it is there to see.
TEST_CASE_FIXTURE(
    LuaFixture,
    "car.extraBytes counts frames longer than their layout per message, with the last "
    "extra bytes") {
  REQUIRE(run("local car = pitwall.cars()[1]\n"
              "assert(next(car.extraBytes) == nil)\n"
              "car.onPosition = function(c, ev) positions = (positions or 0) + 1 end") == "");
  link->carSendsBytes({0x11, 0x27, 0x0e, 0x22, 0x00, 0x00, 0xb8, 0xc1, 0x58, 0x02, 0x47, 0x00, 0x00,
                       0x00, 0x00, 0x58, 0x02, 0xaa});
  link->carSendsBytes({0x12, 0x27, 0x0f, 0x22, 0x00, 0x00, 0xb8, 0xc1, 0x58, 0x02, 0x47, 0x00, 0x00,
                       0x00, 0x00, 0x58, 0x02, 0xbb, 0xcc});
  CHECK(number("positions") == 2);
  CHECK(run("local car = pitwall.cars()[1]\n"
            "local e = car.extraBytes['position-update']\n"
            "assert(e.frames == 2, e.frames)\n"
            "assert(e.last == 'bb cc', e.last)\n"
            "assert(car.malformed == 0 and car.location == 15)") == "");
}

TEST_CASE_FIXTURE(LuaFixture, "state fields are read-only and unknown events are refused by name") {
  CHECK(run("pitwall.cars()[1].speed = 3").find("read-only") != std::string::npos);
  CHECK(run("pitwall.cars()[1].onPostion = function() end").find("not an event") !=
        std::string::npos);
  CHECK(run("pitwall.cars()[1].onPosition = 42").find("must be a function") != std::string::npos);
  CHECK(run("pitwall.cars()[1].setSpeed = print").find("method") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "scripts may keep their own fields on a car") {
  CHECK(run("local c = pitwall.cars()[1]; c.laps = 3; c.laps = c.laps + 1; "
            "assert(pitwall.car(1).laps == 4)") == "");
}

TEST_CASE_FIXTURE(LuaFixture,
                  "an error in a handler is reported with a traceback and the handler stays") {
  REQUIRE(run("calls = 0; pitwall.cars()[1].onBattery = function() calls = calls + 1; "
              "error('flat') end") == "");
  link->carSends(BatteryResponse{3800});
  link->carSends(BatteryResponse{3700});
  CHECK(number("calls") == 2);
  CHECK(host->errorCount() == 2);
  REQUIRE_FALSE(logged.empty());
  CHECK(logged.back().find("onBattery handler of car 1 (skull)") != std::string::npos);
  CHECK(logged.back().find("flat") != std::string::npos);
  CHECK(logged.back().find("stack traceback") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "sleep works in tasks and is refused in callbacks") {
  CHECK(run("t0 = pitwall.now(); pitwall.sleep(1.5); t1 = pitwall.now()") == "");
  CHECK(number("t1") - number("t0") == doctest::Approx(1.5));
  REQUIRE(run("pitwall.cars()[1].onVersion = function() pitwall.sleep(1) end") == "");
  link->carSends(VersionResponse{0x2b70});
  CHECK(logged.back().find("only inside a task") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "timers fire on the engine clock and can be cancelled") {
  CHECK(run("n = 0; local t = pitwall.every(0.25, function() n = n + 1 end)\n"
            "once = nil; pitwall.after(1, function() once = pitwall.now() end)\n"
            "pitwall.after(1.1, function() t:cancel() end)") == "");
  CHECK(number("n") == 4);
  CHECK(number("once") == 1.0);
  CHECK(run("pitwall.every(0, print)").find("> 0") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "a bare coroutine.yield in a task is an error, not a hang") {
  CHECK(run("coroutine.yield()").find("yielded without pitwall.sleep") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "a script that fails to load names the chunk and the line") {
  auto started = host->startString("local x = = 1", "broken.lua");
  REQUIRE_FALSE(started);
  CHECK(started.error().find("broken.lua:1:") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture,
                  "require finds the shipped library; pitwall.sim says it needs the simulator") {
  CHECK(run("local core = require 'pitwall.core'; assert(core == pitwall)") == "");
  CHECK(run("require 'pitwall.sim'").find("only available") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "a reused event table shows each event's values, changed or not") {
  REQUIRE(run("seen = {}\n"
              "pitwall.cars()[1].onPosition = function(c, ev)\n"
              "  seen[#seen + 1] = string.format('%d/%d/%d/%s', ev.piece, ev.location, ev.speed, "
              "tostring(ev.reverse))\n"
              "end") == "");
  PositionUpdate p;
  p.piece_id = 17, p.location_id = 1, p.speed_mm_s = 500;
  link->carSends(p);
  p.location_id = 2;  // only the location changes
  link->carSends(p);
  p.piece_id = 18, p.parsing_flags = 0x20;
  link->carSends(p);
  p.parsing_flags = 0;  // back to what an earlier event had
  link->carSends(p);
  CHECK(run("assert(table.concat(seen, ' ') == '17/1/500/false 17/2/500/false 18/2/500/true "
            "18/2/500/false', table.concat(seen, ' '))") == "");
}

namespace {
CaptureLink* g_injectInto = nullptr;
}

TEST_CASE_FIXTURE(
    LuaFixture,
    "an event delivered while a handler runs is complete and does not leak into the next") {
  // inject(piece) makes the car send a position update at once, from inside a handler.
  g_injectInto = link;
  lua_pushcfunction(host->state(), [](lua_State* L) {
    PositionUpdate p;
    p.piece_id = static_cast<std::uint8_t>(lua_tointeger(L, 1));
    p.location_id = 4;
    p.speed_mm_s = 321;
    g_injectInto->carSends(p);
    return 0;
  });
  lua_setglobal(host->state(), "inject");
  REQUIRE(run("seen = {}\n"
              "local car = pitwall.cars()[1]\n"
              "car.onPosition = function(c, ev) seen[#seen + 1] = ev.piece .. '/' .. ev.speed end\n"
              "car.onBattery = function(c, ev) inject(40); seen[#seen + 1] = 'mv ' .. "
              "ev.millivolts end") == "");
  PositionUpdate first;
  first.piece_id = 17, first.speed_mm_s = 500;
  link->carSends(first);                  // top level: interned keys
  link->carSends(BatteryResponse{3777});  // its handler injects a nested position update
  link->carSends(first);                  // top level again: must not keep the nested values
  CHECK(run("assert(table.concat(seen, ' ') == '17/500 40/321 mv 3777 17/500', "
            "table.concat(seen, ' '))") == "");
  g_injectInto = nullptr;
}

TEST_CASE("a car that connects after the script started joins it: pitwall.onCar, then onConnect") {
  // Real cars: the run starts with every car found, some not connected yet (docs/bluetooth.md).
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  auto owned = std::make_unique<CaptureLink>();
  CaptureLink* link = owned.get();
  fleet.add(std::move(owned), CarIdentity{0, "skull", 9, 1});
  setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
  ScriptHost host(loop, fleet, nullptr, HostOptions{});
  REQUIRE(
      host.startString("joined, connects = {}, 0\n"
                       "local car = pitwall.cars()[1]\n"
                       "assert(not car.connected)\n"
                       "car.onConnect = function() connects = connects + 1 end\n"
                       "pitwall.onCar = function(c) joined[#joined + 1] = c.name end\n",
                       "join.lua"));
  loop.run();
  link->setConnected(true);
  loop.run();
  lua_State* L = host.state();
  CHECK(luaL_dostring(L, "return #joined == 1 and joined[1] == 'skull' and connects == 1") ==
        LUA_OK);
  CHECK(lua_toboolean(L, -1));
  // a reconnection is an onConnect, not a second join
  link->setConnected(false);
  link->setConnected(true);
  loop.run();
  CHECK(luaL_dostring(L, "return #joined == 1 and connects == 2") == LUA_OK);
  CHECK(lua_toboolean(L, -1));
}

TEST_CASE_FIXTURE(LuaFixture,
                  "listeners run before the car's handler, in order, on the same event") {
  REQUIRE(run("order = {}\n"
              "local car = pitwall.cars()[1]\n"
              "a = pitwall.listen(car, 'onBattery', function(c, ev)"
              " order[#order + 1] = 'a' .. ev.millivolts end)\n"
              "pitwall.listen(car, 'onBattery', function(c, ev)"
              " order[#order + 1] = 'b' .. ev.millivolts; assert(c == car) end)\n"
              "car.onBattery = function(c, ev) order[#order + 1] = 'h' .. ev.millivolts end") ==
          "");
  link->carSends(BatteryResponse{3800});
  CHECK(run("assert(table.concat(order, ' ') == 'a3800 b3800 h3800', table.concat(order, ' '))") ==
        "");
  // cancelled: gone from the next event on; a second cancel says it was not active
  CHECK(run("assert(a:cancel() == true and a:cancel() == false); order = {}") == "");
  link->carSends(BatteryResponse{3700});
  CHECK(run("assert(table.concat(order, ' ') == 'b3700 h3700', table.concat(order, ' '))") == "");
}

TEST_CASE_FIXTURE(LuaFixture, "a listener without a handler, and a handler after every cancel") {
  REQUIRE(run("seen, handled = 0, 0\n"
              "local car = pitwall.cars()[1]\n"
              "sub = pitwall.listen(car, 'onPing', function() seen = seen + 1 end)") == "");
  link->carSends(PingResponse{});
  CHECK(number("seen") == 1);
  REQUIRE(run("sub:cancel(); pitwall.cars()[1].onPing = function() handled = handled + 1 end") ==
          "");
  link->carSends(PingResponse{});
  CHECK(number("seen") == 1);
  CHECK(number("handled") == 1);
}

TEST_CASE_FIXTURE(LuaFixture,
                  "an error in a listener is reported; the others and the handler run") {
  REQUIRE(run("calls = 0\n"
              "local car = pitwall.cars()[1]\n"
              "pitwall.listen(car, 'onBattery', function() error('broken listener') end)\n"
              "pitwall.listen(car, 'onBattery', function() calls = calls + 1 end)\n"
              "car.onBattery = function() calls = calls + 10 end") == "");
  link->carSends(BatteryResponse{3800});
  CHECK(number("calls") == 11);
  CHECK(host->errorCount() == 1);
  REQUIRE_FALSE(logged.empty());
  CHECK(logged.back().find("onBattery listener of car 1 (skull)") != std::string::npos);
  CHECK(logged.back().find("broken listener") != std::string::npos);
  CHECK(logged.back().find("stack traceback") != std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "a listener added during an event hears from the next one") {
  REQUIRE(run("late = 0\n"
              "local car = pitwall.cars()[1]\n"
              "pitwall.listen(car, 'onPing', function(c)\n"
              "  if not added then added = true; pitwall.listen(c, 'onPing', function()"
              " late = late + 1 end) end\n"
              "end)") == "");
  link->carSends(PingResponse{});
  CHECK(number("late") == 0);
  link->carSends(PingResponse{});
  CHECK(number("late") == 1);
}

TEST_CASE_FIXTURE(LuaFixture,
                  "listening is refused clearly for unknown events, onMessage, non-cars") {
  CHECK(run("pitwall.listen(pitwall.cars()[1], 'onPostion', print)").find("onPosition, ") !=
        std::string::npos);
  CHECK(run("pitwall.listen(pitwall.cars()[1], 'onMessage', print)")
            .find("onMessage only through car.onMessage") != std::string::npos);
  CHECK(run("pitwall.listen({}, 'onPing', print)").find("expected a car") != std::string::npos);
  CHECK(run("pitwall.listen(pitwall.cars()[1], 'onPing', 42)").find("must be a function") !=
        std::string::npos);
}

TEST_CASE_FIXTURE(LuaFixture, "pitwall.piece tells what a road piece is") {
  CHECK(run("local p = pitwall.piece(34); assert(p.type == 'start-long' and p.length == 340)\n"
            "p = pitwall.piece(33); assert(p.type == 'start-short' and p.length == 220)\n"
            "p = pitwall.piece(39); assert(p.type == 'straight' and p.length == 560)\n"
            "p = pitwall.piece(17); assert(p.type == 'curve' and p.radius == 280)\n"
            "assert(math.abs(p.length - 280 * math.pi / 2) < 1e-9)\n"
            "assert(pitwall.piece(99) == nil and pitwall.piece(-1) == nil)") == "");
}
