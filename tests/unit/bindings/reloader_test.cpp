// Hot reload (docs/hot-reload.md), in virtual time over simulated cars: a new version takes over
// the cars, persisted state survives, a broken version never does, and no event is lost,
// duplicated or handled by a version that is gone.
#include "bindings/reloader.hpp"

#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "engine/core/log.hpp"
#include "engine/protocol/anki/messages.hpp"
#include "engine/sim/grid.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

struct ReloadFixture {
  Loop loop;
  SimSession sim;
  Fleet fleet{loop};
  std::unique_ptr<Reloader> scripts;
  fs::path dir;
  std::vector<std::string> logged;
  long positions = 0;  // position updates the cars sent, counted below Lua
  Subscription counting;

  explicit ReloadFixture(ClockKind clock = ClockKind::Virtual, int cars = 2) : loop(clock) {
    setenv("PITWALL_SCRIPTS", PITWALL_SOURCE_DIR "/scripts", 1);
    dir = fs::temp_directory_path() / ("pitwall-reload-" + std::to_string(::getpid()) + "-" +
                                       std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    fs::create_directories(dir);
    sim.world = std::make_unique<sim::World>(loop, *sim::loadLayout("oval"), 1);
    // these tests count the events a script hears across reloads: every code makes one
    sim.world->setSensor(sim::SensorModel::Ideal);
    for (int i = 0; i < cars; ++i)
      testing::addSimulatedCar(loop, fleet, *sim.world, sim::gridSpec(sim.world->track(), i));
    counting = fleet.frames.connect([this](AnkiCar&, AnkiCar::Direction d,
                                           std::span<const std::uint8_t>, const anki::Message& m) {
      if (d == AnkiCar::Direction::Rx && std::holds_alternative<anki::PositionUpdate>(m))
        ++positions;
    });
    runFor(1s);  // the cars connect
    REQUIRE(fleet.connectedCount() == static_cast<std::size_t>(cars));
    scripts = std::make_unique<Reloader>(loop, fleet, &sim, HostOptions{});
    log::setSink([this](log::Level, std::string_view line) { logged.emplace_back(line); });
  }
  ~ReloadFixture() {
    log::setSink(nullptr);
    scripts.reset();
    fs::remove_all(dir);
  }

  std::string write(const std::string& name, const std::string& code) {
    fs::path p = dir / name;
    std::ofstream(p) << code;
    return p.string();
  }
  void runFor(Duration d) {
    auto id = loop.after(d, [this] { loop.stop(); });
    loop.run();
    loop.cancel(id);
  }
  // A value of the current version's world, by a Lua expression.
  double number(const std::string& expr) {
    lua_State* L = scripts->host().state();
    REQUIRE(luaL_dostring(L, ("return " + expr).c_str()) == LUA_OK);
    double v = lua_tonumber(L, -1);
    lua_pop(L, 1);
    return v;
  }
  std::string text(const std::string& expr) {
    lua_State* L = scripts->host().state();
    REQUIRE(luaL_dostring(L, ("return " + expr).c_str()) == LUA_OK);
    std::string v = lua_tostring(L, -1) ? lua_tostring(L, -1) : "(nil)";
    lua_pop(L, 1);
    return v;
  }
  double simSpeed(int i) { return sim.world->cars()[i]->truth().speed_mm_s; }
};

// A version of a script: every position event counted once in persist, by version.
std::string counting(int version, int speed) {
  return "local p = pitwall.persist\n"
         "p.count = p.count or 0\n"
         "p.byVersion = p.byVersion or {}\n"
         "p.byVersion[" +
         std::to_string(version) +
         "] = 0\n"
         "for _, car in ipairs(pitwall.cars()) do\n"
         "  car:setSpeed(" +
         std::to_string(speed) +
         ")\n"
         "  car.onPosition = function()\n"
         "    p.count = p.count + 1\n"
         "    p.byVersion[" +
         std::to_string(version) + "] = p.byVersion[" + std::to_string(version) +
         "] + 1\n"
         "  end\n"
         "end\n";
}

}  // namespace

TEST_CASE("a rewritten script takes over the running cars with its new behaviour") {
  ReloadFixture f;
  auto script = f.write("race.lua", counting(1, 400));
  REQUIRE(f.scripts->start(script));
  f.runFor(3s);
  CHECK(f.simSpeed(0) == doctest::Approx(400).epsilon(0.05));
  CHECK(f.number("pitwall.persist.byVersion[1]") > 10);

  f.write("race.lua", counting(2, 800));
  REQUIRE(f.scripts->reload());
  CHECK(f.number("pitwall.reloads") == 1);
  double v1AtReload = f.number("pitwall.persist.byVersion[1]");
  f.runFor(3s);
  CHECK(f.simSpeed(0) == doctest::Approx(800).epsilon(0.05));
  CHECK(f.number("pitwall.persist.byVersion[2]") > 10);
  CHECK(f.number("pitwall.persist.byVersion[1]") == v1AtReload);  // the old handlers are gone
  CHECK(f.scripts->stats().reloads == 1);
}

TEST_CASE("no event is lost or duplicated across repeated reloads") {
  ReloadFixture f;
  auto script = f.write("race.lua", counting(1, 900));
  REQUIRE(f.scripts->start(script));
  long before = f.positions;  // (none so far reached Lua before the script started)
  f.runFor(2s);               // up to speed
  for (int v = 2; v <= 12; ++v) {
    f.runFor(std::chrono::milliseconds(170 + 37 * v));  // reloads at uneven moments
    f.write("race.lua", counting(v, 900));
    REQUIRE(f.scripts->reload());
  }
  f.runFor(1s);
  CHECK(f.positions - before > 50);
  CHECK(f.number("pitwall.persist.count") == f.positions - before);
  double sum = 0;
  for (int v = 1; v <= 12; ++v) {
    double n = f.number("pitwall.persist.byVersion[" + std::to_string(v) + "]");
    CHECK(n > 0);
    sum += n;
  }
  CHECK(sum == f.number("pitwall.persist.count"));
}

TEST_CASE("persisted state survives: tables, shared and cyclic ones, and cars") {
  ReloadFixture f;
  auto script = f.write("state.lua",
                        "local p = pitwall.persist\n"
                        "p.laps = {3, 5, best = 4.25, name = 'skull', done = false}\n"
                        "p.same = p.laps\n"
                        "p.loop = {}; p.loop.self = p.loop\n"
                        "p.leader = pitwall.cars()[2]\n"
                        "p[7] = 'seven'\n"
                        "p.big = math.maxinteger\n"
                        "p.fn = function() end\n"
                        "p.deep = {co = coroutine.create(print)}\n");
  REQUIRE(f.scripts->start(script));
  f.write("state.lua", "-- version 2 reads what version 1 left\n");
  REQUIRE(f.scripts->reload());
  CHECK(f.number("pitwall.persist.laps[1] + pitwall.persist.laps[2]") == 8);
  CHECK(f.number("pitwall.persist.laps.best") == 4.25);
  CHECK(f.text("pitwall.persist.laps.name") == "skull");
  CHECK(f.text("tostring(pitwall.persist.laps.done)") == "false");
  CHECK(f.text("tostring(pitwall.persist.same == pitwall.persist.laps)") == "true");
  CHECK(f.text("tostring(pitwall.persist.loop.self == pitwall.persist.loop)") == "true");
  CHECK(f.text("tostring(pitwall.persist.leader == pitwall.cars()[2])") == "true");
  CHECK(f.text("pitwall.persist[7]") == "seven");
  CHECK(f.text(
            "math.type(pitwall.persist.big) .. tostring(pitwall.persist.big == math.maxinteger)") ==
        "integertrue");
  // What cannot cross is named, not silently lost.
  CHECK(f.text("tostring(pitwall.persist.fn)") == "nil");
  std::string all;
  for (const auto& l : f.logged) all += l + "\n";
  CHECK(all.find("pitwall.persist.fn (a function) cannot cross") != std::string::npos);
  CHECK(all.find("pitwall.persist.deep.co (a thread) cannot cross") != std::string::npos);
}

TEST_CASE(
    "a persisted list of cars crosses as a list of cars, without a word about its metatable") {
  ReloadFixture f;
  auto script = f.write("list.lua", "pitwall.persist.grid = pitwall.cars()\n");
  REQUIRE(f.scripts->start(script));
  f.write("list.lua", "-- version 2\n");
  REQUIRE(f.scripts->reload());
  CHECK(f.text("tostring(pitwall.persist.grid[2] == pitwall.cars()[2])") == "true");
  std::string all;
  for (const auto& l : f.logged) all += l + "\n";
  CHECK(all.find("metatable") == std::string::npos);
  // still one: used past its end, it names the cars it holds
  lua_State* L = f.scripts->host().state();
  const char* code = "local grid = pitwall.persist.grid\nreturn grid[3].speed";
  REQUIRE(luaL_loadbufferx(L, code, std::strlen(code), "=list", "t") == LUA_OK);
  std::string error;
  REQUIRE_FALSE(f.scripts->host().callInteractive(0, 0, error));
  CHECK(error.rfind("list:2: this list of cars has no [3]; it holds 1 ", 0) == 0);
}

TEST_CASE("a version that does not compile is refused with file and line; the old one runs on") {
  ReloadFixture f;
  auto script = f.write("race.lua", counting(1, 500));
  REQUIRE(f.scripts->start(script));
  f.runFor(1s);
  f.write("race.lua", "for _, car in ipairs(pitwall.cars()) do\n  car:setSpeed(900)\n  oops(\n");
  auto refused = f.scripts->reload();
  REQUIRE_FALSE(refused);
  CHECK(refused.error().find("race.lua:4:") != std::string::npos);
  double before = f.number("pitwall.persist.byVersion[1]");
  f.runFor(2s);
  CHECK(f.number("pitwall.persist.byVersion[1]") > before + 10);
  CHECK(f.simSpeed(0) == doctest::Approx(500).epsilon(0.05));
  CHECK(f.scripts->stats().failures == 1);
  CHECK(f.number("pitwall.reloads") == 0);
}

TEST_CASE("a version that throws while starting, or in onReload, is refused; the old runs on") {
  ReloadFixture f;
  auto script = f.write("race.lua", counting(1, 500));
  REQUIRE(f.scripts->start(script));
  f.runFor(1s);

  SUBCASE("in its main chunk") {
    f.write("race.lua",
            "for _, car in ipairs(pitwall.cars()) do car:setSpeed(1000) end\n"
            "local t = nil\n"
            "print(t.field)\n");
    auto refused = f.scripts->reload();
    REQUIRE_FALSE(refused);
    CHECK(refused.error().find("race.lua:3:") != std::string::npos);
  }
  SUBCASE("in pitwall.onReload") {
    f.write("race.lua",
            "function pitwall.onReload(persist)\n"
            "  error('cannot migrate ' .. tostring(persist.count ~= nil))\n"
            "end\n");
    auto refused = f.scripts->reload();
    REQUIRE_FALSE(refused);
    CHECK(refused.error().find("pitwall.onReload: ") != std::string::npos);
    CHECK(refused.error().find("race.lua:2: cannot migrate true") != std::string::npos);
  }
  double before = f.number("pitwall.persist.byVersion[1]");
  f.runFor(2s);
  CHECK(f.number("pitwall.persist.byVersion[1]") > before + 10);
  // The refused version's commands were sent (it ran), but the old version's events flow on;
  // nothing else of the refused version is left: no handler of it counts.
  CHECK(f.text("tostring(pitwall.onReload)") == "nil");
}

TEST_CASE("timers and tasks of the old version never fire after it") {
  ReloadFixture f;
  auto script = f.write("timers.lua",
                        "local p = pitwall.persist\n"
                        "pitwall.every(0.1, function() p.lastTick = pitwall.now() end)\n"
                        "pitwall.after(5, function() p.late = true end)\n"
                        "pitwall.spawn(function()\n"
                        "  while true do pitwall.sleep(0.05); p.lastTask = pitwall.now() end\n"
                        "end)\n");
  REQUIRE(f.scripts->start(script));
  f.runFor(2s);
  CHECK(f.number("pitwall.persist.lastTick") > 0);
  f.write("timers.lua", "pitwall.persist.reloadedAt = pitwall.now()\n");
  REQUIRE(f.scripts->reload());
  double at = f.number("pitwall.persist.reloadedAt");
  f.runFor(6s);
  CHECK(f.number("pitwall.persist.lastTick") <= at);
  CHECK(f.number("pitwall.persist.lastTask") <= at);
  CHECK(f.text("tostring(pitwall.persist.late)") == "nil");
}

TEST_CASE("onUnload of the old version, then the new main chunk, then its onReload") {
  ReloadFixture f;
  std::string code =
      "local p = pitwall.persist\n"
      "p.order = p.order or {}\n"
      "table.insert(p.order, 'main' .. (pitwall.reloads + 1))\n"
      "function pitwall.onUnload(persist)\n"
      "  table.insert(persist.order, 'unload' .. (pitwall.reloads + 1))\n"
      "end\n"
      "function pitwall.onReload(persist, info)\n"
      "  table.insert(persist.order, 'reload' .. info.reloads .. ':' .. #info.files)\n"
      "end\n";
  auto script = f.write("order.lua", code);
  REQUIRE(f.scripts->start(script));
  REQUIRE(f.scripts->reload({script}));
  REQUIRE(f.scripts->reload({script}));
  CHECK(f.text("table.concat(pitwall.persist.order, ' ')") ==
        "main1 unload1 main2 reload1:1 unload2 main3 reload2:1");
}

TEST_CASE("saving the script or one of its modules reloads it (inotify, real time)") {
  ReloadFixture f(ClockKind::Real, 1);
  f.write("helper.lua", "return {speed = 300}\n");
  auto script = f.write("main.lua",
                        "local helper = require 'helper'\n"
                        "pitwall.persist.speed = helper.speed\n");
  REQUIRE(f.scripts->start(script));
  REQUIRE(f.scripts->watch(20ms));
  CHECK(f.number("pitwall.persist.speed") == 300);

  auto waitForReloads = [&](int n) {
    auto give_up = f.loop.after(10s, [&] { f.loop.stop(); });
    f.scripts->onNewVersion = [&](ScriptHost&) {
      if (f.scripts->stats().reloads >= n) f.loop.stop();
    };
    f.loop.run();
    f.loop.cancel(give_up);
    return f.scripts->stats().reloads >= n;
  };

  // An editor's atomic save: write a new file, rename it over the module.
  { std::ofstream(f.dir / "helper.lua.tmp") << "return {speed = 700}\n"; }
  fs::rename(f.dir / "helper.lua.tmp", f.dir / "helper.lua");
  REQUIRE(waitForReloads(1));
  CHECK(f.number("pitwall.persist.speed") == 700);

  f.write("main.lua", "pitwall.persist.speed = 1\n");
  REQUIRE(waitForReloads(2));
  CHECK(f.number("pitwall.persist.speed") == 1);
}

TEST_CASE("pitwall.stop() in a new version's first run ends the run once it took over") {
  ReloadFixture f;
  int stops = 0;
  f.scripts->onStopRequested = [&] { ++stops; };
  auto script = f.write("once.lua", counting(1, 500));
  REQUIRE(f.scripts->start(script));
  f.write("once.lua", "pitwall.persist.done = true\npitwall.stop()\n");
  REQUIRE(f.scripts->reload());
  CHECK(stops == 1);
  // A refused version's stop is not obeyed.
  f.write("once.lua", "pitwall.stop()\nerror('no')\n");
  REQUIRE_FALSE(f.scripts->reload());
  CHECK(stops == 1);
}

TEST_CASE("the library's carried state crosses quietly; a failing carrier is reported") {
  ReloadFixture f;
  // A module's state with methods, a metatable, a shared table and a car in it: the data
  // crosses, the functions and metatables stay behind without a warning.
  auto script =
      f.write("race.lua",
              "local Thing = {__index = {}}\n"
              "local shared = {n = 7}\n"
              "local state = setmetatable({a = shared, b = shared, car = pitwall.cars()[2],\n"
              "  fn = function() end, list = {1, 2.5, 'x'}}, Thing)\n"
              "pitwall._carry('thing', function() return state end)\n"
              "pitwall._carry('broken', function() error('cannot save') end)\n"
              "carried = pitwall._takeCarried('thing')\n");
  REQUIRE(f.scripts->start(script));
  CHECK(f.text("tostring(carried)") == "nil");  // a first version finds nothing
  f.logged.clear();
  REQUIRE(f.scripts->reload());
  CHECK(f.number("carried.a.n") == 7);
  CHECK(f.text("tostring(carried.a == carried.b)") == "true");
  CHECK(f.text("tostring(carried.car == pitwall.cars()[2])") == "true");
  CHECK(f.text("tostring(carried.fn)") == "nil");
  CHECK(f.text("tostring(getmetatable(carried))") == "nil");
  CHECK(f.text("carried.list[3] .. math.type(carried.list[1])") == "xinteger");
  std::string log;
  for (const auto& l : f.logged) log += l + "\n";
  CHECK(log.find("cannot cross") == std::string::npos);
  CHECK(log.find("carrying broken into the new version") != std::string::npos);
  CHECK(log.find("cannot save") != std::string::npos);
  CHECK(f.scripts->stats().reloads == 1);  // a carrier's error does not refuse the version
}
