#include "engine/cli/league_heat.hpp"

#include <lua.hpp>

#include <chrono>

#include "bindings/lua_json.hpp"
#include "engine/cli/session.hpp"
#include "engine/sim/sensor.hpp"

namespace pitwall::cli {

namespace {

// The heat, as the race library runs it: LEAGUE holds the spec; its rows go back into it. The
// race has a time cap (`seconds`), so a heat whose drivers never finish ends too.
constexpr const char* kHeat = R"(
local sim = require "pitwall.sim"
local race = require "pitwall.race"
local spec = LEAGUE
local cars = {}
for i = 1, #spec.files do cars[i] = sim.addCar {} end
-- spec.trace: car 1's lap, lap distance and speed as the simulator knows them, every 0.05 s
local trace
if spec.trace then
  trace = {}
  pitwall.every(0.05, function()
    local t = sim.truth(cars[1])
    trace[#trace + 1] = { time = pitwall.now(), lap = t.laps, distance = t.lapDistance,
      speed = t.speed }
  end)
end
local session = race[spec.qualifying and "qualifying" or "laps"] {
  laps = spec.laps, drivers = spec.files, board = false, title = spec.title,
  seconds = spec.cap, finishTimeout = 30 }
local rows = {}
for _, r in ipairs(session:results()) do
  local e = session:entry(cars[r.number])
  local times = {}
  for k, lap in ipairs(e.timer.history) do
    if k > r.laps then break end
    times[k] = lap.time
  end
  rows[#rows + 1] = { number = r.number, car = r.car, position = r.position, status = r.status,
    reason = r.reason, finished = r.finished, laps = r.laps, bestLap = r.bestLap,
    totalTime = r.totalTime, lapTimes = times }
end
spec.results = trace and { rows = rows, trace = trace } or rows
pitwall.stop()
)";

void pushSpec(lua_State* L, const HeatSpec& spec, double cap) {
  lua_createtable(L, 0, 6);
  lua_createtable(L, static_cast<int>(spec.files.size()), 0);
  for (std::size_t i = 0; i < spec.files.size(); ++i) {
    lua_pushlstring(L, spec.files[i].data(), spec.files[i].size());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  lua_setfield(L, -2, "files");
  lua_pushboolean(L, spec.qualifying);
  lua_setfield(L, -2, "qualifying");
  lua_pushinteger(L, spec.laps);
  lua_setfield(L, -2, "laps");
  lua_pushnumber(L, cap);
  lua_setfield(L, -2, "cap");
  lua_pushlstring(L, spec.title.data(), spec.title.size());
  lua_setfield(L, -2, "title");
  lua_pushboolean(L, spec.trace);
  lua_setfield(L, -2, "trace");
  lua_setglobal(L, "LEAGUE");
}

}  // namespace

ScenarioResult runHeat(const HeatSpec& spec) {
  ScenarioResult out;
  out.seed = spec.seed;
  const auto begin = std::chrono::steady_clock::now();
  auto track = sim::loadLayout(spec.track);
  if (!track) {
    out.status = ScenarioResult::Status::Errored;
    out.message = track.error();
    return out;
  }
  Session session(ClockKind::Virtual, std::move(*track), spec.seed);
  session.sim().world->setSensor(
      sim::sensorModelNamed(spec.sensor).value_or(sim::SensorModel::Real));
  HostOptions host;
  host.seed = spec.seed;
  host.library_frames = false;
  host.driverLimits = spec.limits;
  host.driverLimits.watch = false;
  // A lap of the slowest sensible driver is well under 30 s; the lights and the grid take 10.
  const double cap = 30.0 * spec.laps + 10;
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    out.status = ScenarioResult::Status::Errored;
    out.message = e.what();
    return out;
  }
  Loop& loop = session.loop();
  bool timedOut = false;
  loop.after(fromSeconds(cap + 120), [&] {  // the race's own cap did not end it
    timedOut = true;
    session.finish();
  });
  lua_State* L = session.host().state();
  pushSpec(L, spec, cap);
  if (auto started = session.host().startString(kHeat, "league heat"); !started) {
    out.status = ScenarioResult::Status::Errored;
    out.message = started.error();
    return out;
  }
  loop.run();
  out.simulated = loop.seconds();
  out.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  lua_getglobal(L, "LEAGUE");
  const bool done = lua_istable(L, -1) && lua_getfield(L, -1, "results") == LUA_TTABLE;
  if (!done || timedOut) {
    out.status = ScenarioResult::Status::Errored;
    out.message =
        timedOut
            ? "the heat was still running after " + std::to_string(cap + 120) + " s of virtual time"
            : "the heat ended without results" +
                  (session.host().failure() ? ": " + *session.host().failure() : std::string());
    lua_settop(L, 0);
    return out;
  }
  lua::CopyBudget budget(L, "league heat", std::size_t{64} << 20);
  try {
    // (a driver's error may hold any byte: its reason keeps the rest)
    out.data = lua::toJson(L, -1, {"league heat", "the league"}, budget, "results")
                   .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (const std::exception& e) {
    out.status = ScenarioResult::Status::Errored;
    out.message = e.what();
  }
  lua_settop(L, 0);
  return out;
}

}  // namespace pitwall::cli
