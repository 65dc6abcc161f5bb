// pitwall.sim: the simulated world as a script sees it — its track, its cars, ground truth and
// noise. Scenario tests build their world with it; `require "pitwall.sim"` returns it.
#include <algorithm>
#include <array>
#include <cctype>

#include "bindings/car_binding.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "bindings/track_table.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/limits.hpp"
#include "engine/sim/grid.hpp"
#include "engine/transport/sim_link.hpp"
#include "engine/view/record_laps.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

// The largest record sim.addGhost reads. It is played in the call, on the loop and within the
// script's budget: 512 KiB took 20-35 ms of CPU here (docs/performance.md "Ghosts").
constexpr std::uintmax_t kMaxGhostRecordBytes = 512 * 1024;

SimSession& session(lua_State* L) {
  return *ScriptHost::from(L).sim();
}

sim::SimCar& simCarOf(lua_State* L, int idx) {
  AnkiCar& car = CarBinding::check(L, idx);
  auto* link = dynamic_cast<SimLink*>(&car.link());
  if (!link) throw LuaError(car.label() + " is not a simulated car");
  return link->car();
}

std::uint8_t modelFromLua(lua_State* L, int idx) {
  if (lua_type(L, idx) == LUA_TSTRING) {
    std::string want = lua_tostring(L, idx);
    std::transform(want.begin(), want.end(), want.begin(), ::tolower);
    for (int id = 0; id < 256; ++id) {
      std::string name = anki::modelName(static_cast<std::uint8_t>(id));
      std::transform(name.begin(), name.end(), name.begin(), ::tolower);
      std::replace(name.begin(), name.end(), ' ', '-');
      if (name == want) return static_cast<std::uint8_t>(id);
    }
    throw LuaError("model '" + want + "' is unknown (try groundshock, skull, thermo, nuke, …)");
  }
  auto id = lua::checkInteger(L, idx, "model");
  lua::requireRange("model id", static_cast<double>(id), 0, 255);
  return static_cast<std::uint8_t>(id);
}

int track(lua_State* L) {
  pushTrackTable(L, session(L).world->track());
  return 1;
}

int setTrack(lua_State* L) {
  std::string what = lua::checkString(L, 1, "track layout (a name, a file or layout text)");
  SimSession& s = session(L);
  if (!s.world->cars().empty())
    throw LuaError("the track cannot change once cars are on it; call sim.setTrack first");
  // A layout name, a file, or the layout text itself.
  auto loaded = sim::loadLayout(what);
  if (!loaded && what.find(' ') != std::string::npos) loaded = sim::parseLayout(what);
  if (!loaded) throw LuaError(loaded.error());
  sim::Noise noise = s.world->noise();
  Loop& loop = s.world->loop();
  sim::SensorModel sensor = s.world->sensor();
  s.world = std::make_unique<sim::World>(loop, std::move(*loaded), s.seed);
  s.world->setNoise(noise);
  s.world->setSensor(sensor);
  pushTrackTable(L, s.world->track());
  return 1;
}

int layouts(lua_State* L) {
  auto names = sim::layoutNames();
  lua_createtable(L, static_cast<int>(names.size()), 0);
  for (std::size_t i = 0; i < names.size(); ++i) {
    lua_pushstring(L, names[i].c_str());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i) + 1);
  }
  return 1;
}

// A car is put on the road: within ±70 mm of its centre (seed 000 §4.3.4.4), the offsets car
// commands take (limits.hpp). A car steered further, which only raw frames can do, drives on to
// the simulator's road edge (docs/simulator.md "Delocalization").
void checkOnRoad(double offset_mm) {
  using anki::limits::kOffsetMax, anki::limits::kOffsetMin;
  if (!(offset_mm >= kOffsetMin && offset_mm <= kOffsetMax))  // NaN too
    throw LuaError("offset " + lua::show(offset_mm) + " mm is off the road (" +
                   std::to_string(static_cast<int>(kOffsetMin)) + ".." +
                   std::to_string(static_cast<int>(kOffsetMax)) + " mm)");
}

// A simulated car made by the world joins the run over a SimLink, and is pushed.
int join(lua_State* L, const sim::CarSpec& spec) {
  ScriptHost& host = ScriptHost::from(L);
  sim::SimCar& simCar = session(L).world->addCar(spec);
  auto link = std::make_unique<SimLink>(host.loop(), simCar);
  SimLink& toCar = *link;
  AnkiCar& car = host.fleet().add(
      std::move(link),
      CarIdentity{0, spec.name, spec.model_id, simCar.identifier(), static_cast<bool>(spec.ghost)});
  toCar.connect();  // now that the fleet listens: the car joins the run (pitwall.onCar) here
  host.cars().bind(car);
  host.cars().push(L, car);
  return 1;
}

// sim._addCar{name=, model=, piece=, distance=, lane= | offset=, battery=, firmware=}
int addCar(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  SimSession& s = *host.sim();
  static constexpr std::array<const char*, 8> kOptions = {"name", "model",  "piece",   "distance",
                                                          "lane", "offset", "battery", "firmware"};
  lua::Options read(L, 1, "sim.addCar", kOptions, "name=, model=, piece=, lane=, …");
  const sim::Track& track = s.world->track();
  int index = static_cast<int>(s.world->cars().size());
  sim::CarSpec spec = sim::gridSpec(track, index);
  if (read.value("model")) {
    spec.model_id = modelFromLua(L, -1);
    lua_pop(L, 1);
  }
  if (auto piece = read.integer("piece", 1, static_cast<long long>(track.size()), {},
                                "an index into the track's pieces")) {
    spec.piece_index = static_cast<std::size_t>(*piece - 1);
    spec.distance_mm = 0;
  } else if (index >= sim::gridCapacity(track)) {
    // the next grid slot would be one a car already stands on
    throw LuaError("the grid of " + track.name() + " is full (" +
                   std::to_string(sim::gridCapacity(track)) +
                   " cars, four on each piece); give this car a place with piece= and lane=");
  }
  if (auto distance = read.number("distance", "distance (mm into the piece)")) {
    spec.distance_mm = *distance;
    double len = track.piece(spec.piece_index).length(spec.offset_mm);
    if (spec.distance_mm < 0 || spec.distance_mm >= len)
      throw LuaError("distance " + lua::show(spec.distance_mm) + " mm is outside the piece (0.." +
                     lua::show(len) + " mm)");
  }
  if (auto lane = read.integer("lane", 1, 4, {}, "1 is leftmost"))
    spec.offset_mm = sim::kLaneOffsets[*lane - 1];
  if (auto offset = read.number("offset", "offset (mm)")) {
    spec.offset_mm = *offset;
    checkOnRoad(spec.offset_mm);
  }
  if (auto mv = read.integer("battery", 3000, 4300, "mV"))
    spec.battery_mv = static_cast<std::uint16_t>(*mv);
  // docs/simulator.md "Firmware families": 0x266e sends the older layouts
  if (auto v = read.integer("firmware", 1, 0xffff, {},
                            "a version as `pitwall scan` shows it, e.g. 0x266e or 0x2b70"))
    spec.version = static_cast<std::uint16_t>(*v);
  std::vector<std::string> taken;
  for (AnkiCar* c : host.fleet().cars()) taken.push_back(c->identity().name);
  spec.name = read.string("name").value_or(anki::uniqueCarName(spec.model_id, taken));
  if (std::find(taken.begin(), taken.end(), spec.name) != taken.end())
    throw LuaError("a car named '" + spec.name + "' is already in the run");

  return join(L, spec);
}

// sim._addGhost{record=, car=, lap=, name=}: the ghost of a recorded lap (docs/simulator.md
// "Ghosts"). The record is read and played here, on the loop: it may be at most
// kMaxGhostRecordBytes (docs/performance.md "Ghosts").
int addGhost(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  SimSession& s = *host.sim();
  static constexpr std::array<const char*, 4> kOptions = {"record", "car", "lap", "name"};
  lua::Options read(L, 1, "sim.addGhost", kOptions, "record=, car=, lap=, name=");
  auto record = read.string("record", "record (a --record file)");
  if (!record) throw LuaError("sim.addGhost needs record=, the --record file that holds the lap");
  view::LapAsk ask;
  if (read.value("car")) {
    if (lua_type(L, -1) == LUA_TNUMBER && lua_isinteger(L, -1))
      ask.car = std::to_string(lua_tointeger(L, -1));
    else if (lua_type(L, -1) == LUA_TSTRING)
      ask.car = lua_tostring(L, -1);
    else
      throw LuaError("sim.addGhost: car= must be the recorded car's number or name, not a " +
                     std::string(luaL_typename(L, -1)));
    lua_pop(L, 1);
  }
  if (read.value("lap")) {
    const bool best =
        lua_type(L, -1) == LUA_TSTRING && std::string_view(lua_tostring(L, -1)) == "best";
    if (lua_type(L, -1) == LUA_TSTRING && !best)
      throw LuaError("sim.addGhost: lap= must be a lap's number or \"best\", not '" +
                     printable(lua_tostring(L, -1), 40) + "'");
    lua_pop(L, 1);
    if (!best)
      ask.lap =
          static_cast<int>(*read.integer("lap", 1, 1000000, {}, "a lap's number, or \"best\""));
  }
  std::vector<std::string> taken;
  for (AnkiCar* c : host.fleet().cars()) taken.push_back(c->identity().name);
  auto ghost = view::ghostSpec(*record, ask, s.world->track(), taken, kMaxGhostRecordBytes);
  if (!ghost) throw LuaError("sim.addGhost: " + ghost.error());
  sim::CarSpec& spec = ghost->spec;
  if (auto name = read.string("name"); name && !name->empty()) {
    if (std::find(taken.begin(), taken.end(), *name) != taken.end())
      throw LuaError("a car named '" + *name + "' is already in the run");
    spec.name = *name;
  }
  log::info("sim", spec.name + " drives " + ghost->what + " again");
  return join(L, spec);
}

int truth(lua_State* L) {
  sim::Truth t = simCarOf(L, 1).truth();
  lua_createtable(L, 0, 16);
  lua::setInteger(L, "pieceIndex", static_cast<lua_Integer>(t.piece_index) + 1);
  lua::setInteger(L, "piece", t.piece_id);
  lua::setNumber(L, "pieceDistance", t.piece_distance_mm);
  lua::setNumber(L, "lapDistance", t.lap_distance_mm);
  lua::setNumber(L, "offset", t.offset_mm);
  lua::setNumber(L, "speed", t.speed_mm_s);
  lua::setNumber(L, "targetSpeed", t.target_speed_mm_s);
  lua::setInteger(L, "laps", t.laps);
  lua::setBoolean(L, "onTrack", t.on_track);
  lua::setBoolean(L, "delocalized", t.delocalized);
  lua::setBoolean(L, "sdkMode", t.sdk_mode);
  lua::setBoolean(L, "connected", t.connected);
  lua::setInteger(L, "battery", t.battery_mv);
  lua::setInteger(L, "collisions", t.collisions);
  lua::setInteger(L, "slides", t.slides);
  lua::setInteger(L, "speedCommands", t.speed_commands);
  lua::setInteger(L, "stopCommands", t.stop_commands);
  return 1;
}

int lift(lua_State* L) {
  simCarOf(L, 1).lift();
  return 0;
}

int reboot(lua_State* L) {
  double seconds = lua::optNumber(L, 2, "seconds (the car is away)", 3);
  lua::requireRange("seconds", seconds, 0, 600);
  simCarOf(L, 1).reboot(
      std::chrono::duration_cast<Duration>(std::chrono::duration<double>(seconds)));
  return 0;
}

int place(lua_State* L) {
  sim::SimCar& car = simCarOf(L, 1);
  const sim::Track& track = session(L).world->track();
  auto piece = lua::checkInteger(L, 2, "piece (index into the track, from 1)");
  lua::requireRange("piece", static_cast<double>(piece), 1, static_cast<double>(track.size()));
  double offset = lua::optNumber(L, 3, "offset (mm)", 0);
  checkOnRoad(offset);
  car.place(static_cast<std::size_t>(piece - 1), offset);
  return 0;
}

int noise(lua_State* L) {
  SimSession& s = session(L);
  sim::Noise n = s.world->noise();
  static constexpr std::array<const char*, 3> kOptions = {"drop", "late", "lateBy"};
  lua::Options read(L, 1, "sim.noise", kOptions, "drop=, late=, lateBy=");
  if (read.given()) {
    n.drop = read.number("drop", 0, 1, {}, "a probability").value_or(n.drop);
    n.late = read.number("late", 0, 1, {}, "a probability").value_or(n.late);
    if (auto by = read.number("lateBy", 0, 10, "s")) n.late_by = fromSeconds(*by);
    s.world->setNoise(n);
  }
  lua_createtable(L, 0, 3);
  lua::setNumber(L, "drop", n.drop);
  lua::setNumber(L, "late", n.late);
  lua::setNumber(L, "lateBy", toSeconds(n.late_by));
  return 1;
}

// sim.sensor{model = "real"|"ideal"|"transitions"}: what the cars' sensors report
// (docs/simulator.md "Sensor model"); returns the current setting.
int sensor(lua_State* L) {
  SimSession& s = session(L);
  static constexpr std::array<const char*, 1> kOptions = {"model"};
  lua::Options read(L, 1, "sim.sensor", kOptions, "model = \"real\", \"ideal\" or \"transitions\"");
  if (auto name = read.string("model", "sensor model")) {
    auto model = sim::sensorModelNamed(*name);
    if (!model)
      throw LuaError("sensor model '" + printable(*name, 40) +
                     "' is not one the simulator has; use \"real\" (fitted to real cars: "
                     "positions thin out with speed), \"ideal\" (every code) or "
                     "\"transitions\" (no position update at all: the worst case)");
    s.world->setSensor(*model);
  }
  lua_createtable(L, 0, 1);
  std::string_view name = sim::sensorModelName(s.world->sensor());
  lua_pushlstring(L, name.data(), name.size());
  lua_setfield(L, -2, "model");
  return 1;
}

}  // namespace

void openSimModule(ScriptHost& host) {
  lua_State* L = host.state();
  static const luaL_Reg functions[] = {
      {"track", lua::guarded<track>},        {"setTrack", lua::guarded<setTrack>},
      {"layouts", lua::guarded<layouts>},    {"_addCar", lua::guarded<addCar>},
      {"_addGhost", lua::guarded<addGhost>}, {"truth", lua::guarded<truth>},
      {"lift", lua::guarded<lift>},          {"reboot", lua::guarded<reboot>},
      {"place", lua::guarded<place>},        {"noise", lua::guarded<noise>},
      {"sensor", lua::guarded<sensor>},      {nullptr, nullptr}};
  lua_getglobal(L, "pitwall");
  luaL_newlib(L, functions);
  openScriptUnderTest(L);
  lua_setfield(L, -2, "sim");
  lua_pop(L, 1);
}

}  // namespace pitwall
