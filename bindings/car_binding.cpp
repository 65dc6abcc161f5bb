#include "bindings/car_binding.hpp"

#include "bindings/car_proxy.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

#include "bindings/lua_object.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/message_json.hpp"

namespace pitwall {

using namespace anki;
using lua::LuaError;

namespace {

constexpr const char* kMetatable = "pitwall.car";

constexpr std::array<const char*, kCarEventCount> kEventNames = {
    PITWALL_CAR_EVENTS(PITWALL_EVENT_NAME)};

}  // namespace

const lua::EventNames& carEvents() {
  static const lua::EventNames names(kEventNames);
  return names;
}

namespace {
const lua::TypeSpec& carType();
}  // namespace

namespace {

CarBinding::Proxy& proxyAt(lua_State* L, int idx) {
  return *lua::check<CarBinding::Proxy*>(L, idx, carType());
}

// Narrows a Lua integer for AnkiCar, whose range check then names the value: anything beyond
// ±1e6 is out of every command's range and is reported as ±1e6 rather than wrapped.
int toInt(long long v) {
  return static_cast<int>(std::clamp(v, -1000000LL, 1000000LL));
}

// ---- methods ----
int setSpeed(lua_State* L) {
  AnkiCar& car = CarBinding::command(L, 1);
  auto speed = lua::checkRounded(L, 2, "speed (mm/s)");
  auto accel = lua::optRounded(L, 3, "acceleration (mm/s²)", kDefaultAccel);
  bool limit = lua_toboolean(L, 4);
  return lua::raiseIfRefused(car.setSpeed(toInt(speed), toInt(accel), limit));
}
int changeLane(lua_State* L) {
  AnkiCar& car = CarBinding::command(L, 1);
  double offset = lua::checkNumber(L, 2, "offset (mm)");
  auto speed = lua::optRounded(L, 3, "lane-change speed (mm/s)", kDefaultLaneSpeed);
  auto accel = lua::optRounded(L, 4, "lane-change acceleration (mm/s²)", kDefaultLaneAccel);
  return lua::raiseIfRefused(car.changeLane(offset, toInt(speed), toInt(accel)));
}
int setOffset(lua_State* L) {
  AnkiCar& car = CarBinding::command(L, 1);
  return lua::raiseIfRefused(car.setOffset(lua::checkNumber(L, 2, "offset (mm)")));
}
int uturn(lua_State* L) {
  return lua::raiseIfRefused(CarBinding::command(L, 1).turn(TurnType::UTurn));
}
constexpr std::pair<const char*, TurnType> kTurnTypes[] = {{"left", TurnType::Left},
                                                           {"right", TurnType::Right},
                                                           {"uturn", TurnType::UTurn},
                                                           {"uturn-jump", TurnType::UTurnJump},
                                                           {"none", TurnType::None}};
constexpr std::pair<const char*, TurnTrigger> kTurnTriggers[] = {
    {"immediate", TurnTrigger::Immediate}, {"intersection", TurnTrigger::Intersection}};
int turn(lua_State* L) {
  AnkiCar& car = CarBinding::command(L, 1);
  const TurnType type = lua::checkName(L, 2, "turn type", kTurnTypes);
  const TurnTrigger trigger = lua_isnoneornil(L, 3)
                                  ? TurnTrigger::Immediate
                                  : lua::checkName(L, 3, "turn trigger", kTurnTriggers);
  return lua::raiseIfRefused(car.turn(type, trigger));
}
int lights(lua_State* L) {
  AnkiCar& car = CarBinding::order(L, 1);
  if (lua_istable(L, 2)) {
    // {headlights=true, brake=false, front=…, engine=…}: touched lights in the low nibble,
    // their values in the high nibble (anki-overdrive.md, set lights).
    static constexpr std::array<const char*, 4> kNames = {"headlights", "brake", "front", "engine"};
    lua::Options read(L, 2, "car:lights", kNames, "headlights=, brake=, front=, engine=");
    int mask = 0;
    for (int bit = 0; bit < 4; ++bit)
      if (auto on = read.boolean(kNames[bit])) mask |= (1 << bit) | (*on ? 1 << (bit + 4) : 0);
    return lua::raiseIfRefused(car.lights(mask));
  }
  auto mask = lua::checkInteger(L, 2, "lights mask");
  if (auto e = checkRange("lights mask", static_cast<double>(mask), 0, 255)) throw LuaError(*e);
  return lua::raiseIfRefused(car.lights(static_cast<int>(mask)));
}
// A channel or an effect (the value on top, popped): by name (its position in `names`), or by
// number 0..max.
template <std::size_t N>
std::uint8_t nameOrNumber(lua_State* L, const char* what,
                          const std::pair<const char*, int> (&names)[N], long long max) {
  long long v = 0;
  if (lua_type(L, -1) == LUA_TSTRING) {
    v = lua::checkName(L, -1, what, names);
  } else {
    v = lua::checkInteger(L, -1, what);
    lua::requireRange(what, static_cast<double>(v), 0, static_cast<double>(max));
  }
  lua_pop(L, 1);
  return static_cast<std::uint8_t>(v);
}
constexpr std::pair<const char*, int> kChannels[] = {
    {"red", 0}, {"tail", 1}, {"blue", 2}, {"green", 3}, {"front-left", 4}, {"front-right", 5}};
constexpr std::pair<const char*, int> kEffects[] = {
    {"steady", 0}, {"fade", 1}, {"throb", 2}, {"flash", 3}, {"random", 4}};
int lightsPattern(lua_State* L) {
  AnkiCar& car = CarBinding::order(L, 1);
  if (!lua_istable(L, 2))
    throw LuaError(
        "lightsPattern takes a list of up to 3 channels, e.g. "
        "{{channel='red', effect='throb', from=0, to=14, cycles=5}}");
  LightsPattern p;
  auto n = luaL_len(L, 2);
  if (n < 1 || n > 3)
    throw LuaError("lightsPattern takes 1 to 3 channels, got " + std::to_string(n));
  p.channel_count = static_cast<uint8_t>(n);
  for (int i = 1; i <= n; ++i) {
    lua_geti(L, 2, i);
    const int t = lua_gettop(L);
    if (!lua_istable(L, t))
      throw LuaError("lightsPattern channel " + std::to_string(i) + " must be a table");
    static constexpr std::array<const char*, 5> kOptions = {"channel", "effect", "from", "to",
                                                            "cycles"};
    lua::Options o(L, t, "car:lightsPattern", kOptions, "channel=, effect=, from=, to=, cycles=");
    auto& c = p.channels[i - 1];
    lua_getfield(L, t, "channel");  // required: nil is refused as no channel
    c.channel = nameOrNumber(L, "channel", kChannels, 5);
    c.effect = o.value("effect") ? nameOrNumber(L, "effect", kEffects, 4) : 0;
    c.start = static_cast<uint8_t>(o.integer("from", 0, 14, {}, "an intensity").value_or(0));
    c.end = static_cast<uint8_t>(o.integer("to", 0, 14, {}, "an intensity").value_or(c.start));
    c.cycles_per_10s = static_cast<uint8_t>(o.integer("cycles", 0, 255, "per 10 s").value_or(0));
    lua_settop(L, t - 1);
  }
  return lua::raiseIfRefused(car.lightsPattern(p));
}

// ---- state fields: one entry each (docs/lua-api.md "Car fields") ----

const CarState& stateAt(lua_State* L, int self) {
  return proxyAt(L, self).car->state();
}
const CarIdentity& identityAt(lua_State* L, int self) {
  return proxyAt(L, self).car->identity();
}
// A count or a reading that is not known yet (negative): nil.
void pushKnown(lua_State* L, long long v) {
  if (v < 0)
    lua_pushnil(L);
  else
    lua_pushinteger(L, v);
}
void pushString(lua_State* L, const std::string& v) {
  lua_pushlstring(L, v.data(), v.size());
}

// {connects = 2, drops = 1, lastDrop = "…", rssi = -60, …}, fresh
void pushLink(lua_State* L, int self) {
  const AnkiCar& car = *proxyAt(L, self).car;
  const CarState& s = car.state();
  const LinkHealth h = const_cast<AnkiCar&>(car).link().health();
  lua_createtable(L, 0, 9);
  lua::setInteger(L, "connects", s.connects);
  lua::setInteger(L, "drops", s.drops);
  if (!s.last_drop.empty()) lua::setString(L, "lastDrop", s.last_drop);
  lua::setInteger(L, "writeFailures", h.writeFailures);
  lua::setInteger(L, "stalls", h.stalls);
  if (h.rssi) lua::setInteger(L, "rssi", *h.rssi);
  lua::setInteger(L, "silences", s.silences);
  lua::setNumber(L, "longestSilence", s.longest_silence);
  if (s.round_trip >= 0) lua::setNumber(L, "roundTrip", s.round_trip);
}

// {["position-update"] = {frames = 3, last = "aa"}, …}, fresh
void pushExtraBytes(lua_State* L, int self) {
  const CarState& s = stateAt(L, self);
  lua_createtable(L, 0, static_cast<int>(s.extra_bytes.size()));
  for (const auto& [name, extra] : s.extra_bytes) {
    lua_createtable(L, 0, 2);
    lua::setInteger(L, "frames", static_cast<lua_Integer>(extra.frames));
    lua::setString(L, "last", toHex(extra.last));
    lua_setfield(L, -2, name.c_str());
  }
}

const lua::Field kFields[] = {
    {"speed", [](lua_State* L, int c) { lua_pushinteger(L, stateAt(L, c).speed_mm_s); }},
    {"piece", [](lua_State* L, int c) { pushKnown(L, stateAt(L, c).piece); }},
    {"location", [](lua_State* L, int c) { pushKnown(L, stateAt(L, c).location); }},
    {"offset", [](lua_State* L, int c) { lua_pushnumber(L, stateAt(L, c).offset_mm); }},
    {"name", [](lua_State* L, int c) { pushString(L, identityAt(L, c).name); }},
    {"number", [](lua_State* L, int c) { lua_pushinteger(L, identityAt(L, c).number); }},
    {"model", [](lua_State* L, int c) { pushString(L, modelName(identityAt(L, c).model_id)); }},
    {"modelId", [](lua_State* L, int c) { lua_pushinteger(L, identityAt(L, c).model_id); }},
    {"identifier", [](lua_State* L, int c) { lua_pushinteger(L, identityAt(L, c).identifier); }},
    {"ghost", [](lua_State* L, int c) { lua_pushboolean(L, identityAt(L, c).ghost); }},
    {"address", [](lua_State* L, int c) { pushString(L, proxyAt(L, c).car->link().address()); }},
    {"connected", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).connected); }},
    {"onTrack", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).on_track); }},
    {"onCharger", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).on_charger); }},
    {"delocalized", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).delocalized); }},
    {"reverse", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).reverse); }},
    {"targetSpeed",
     [](lua_State* L, int c) { lua_pushinteger(L, stateAt(L, c).target_speed_mm_s); }},
    {"prevPiece", [](lua_State* L, int c) { pushKnown(L, stateAt(L, c).prev_piece); }},
    {"laneChanging",
     [](lua_State* L, int c) {
       lua_pushboolean(L, stateAt(L, c).lane_change_target_mm.has_value());
     }},
    {"targetOffset",
     [](lua_State* L, int c) {
       const auto& target = stateAt(L, c).lane_change_target_mm;
       target ? lua_pushnumber(L, *target) : lua_pushnil(L);
     }},
    {"batteryLevel",
     [](lua_State* L, int c) {
       const CarState& s = stateAt(L, c);
       pushKnown(L, s.battery_mv > 0 ? s.battery_mv : -1);
     }},
    {"batteryLow", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).battery_low); }},
    {"batteryFull", [](lua_State* L, int c) { lua_pushboolean(L, stateAt(L, c).battery_full); }},
    {"firmware",
     [](lua_State* L, int c) {
       const CarState& s = stateAt(L, c);
       pushKnown(L, s.version > 0 ? s.version : -1);
     }},
    {"lastPing",
     [](lua_State* L, int c) {
       const auto rtt = proxyAt(L, c).car->lastPingRtt();
       rtt ? lua_pushnumber(L, *rtt) : lua_pushnil(L);
     }},
    {"lastPositionTime",
     [](lua_State* L, int c) {
       const CarState& s = stateAt(L, c);
       s.last_position_time < 0 ? lua_pushnil(L) : lua_pushnumber(L, s.last_position_time);
     }},
    {"frames",
     [](lua_State* L, int c) {
       const CarState& s = stateAt(L, c);
       lua_pushinteger(L, static_cast<lua_Integer>(s.frames_in + s.frames_out));
     }},
    {"malformed",
     [](lua_State* L, int c) {
       lua_pushinteger(L, static_cast<lua_Integer>(stateAt(L, c).malformed));
     }},
    {"extraBytes", pushExtraBytes},
    {"link", pushLink},
};

}  // namespace

CarBinding::CarBinding(ScriptHost& host) : host_(host), L_(host.state()), names_(carEvents()) {}

CarBinding::~CarBinding() {
  detach();
}

void CarBinding::attach() {
  if (attached_) return;
  attached_ = true;
  for (auto& [car, proxy] : proxies_) hookEvents(*proxy);
}

void CarBinding::detach() {
  if (!attached_) return;
  attached_ = false;
  for (auto& [car, proxy] : proxies_) unhookEvents(*proxy);
}

namespace {
const lua::TypeSpec& carType() {
  static const luaL_Reg methods[] = {
      {"setSpeed", lua::guarded<setSpeed>},
      {"stop", lua::guarded<lua::command<CarBinding::order, &AnkiCar::stop>>},
      {"changeLane", lua::guarded<changeLane>},
      {"setOffset", lua::guarded<setOffset>},
      {"cancelLaneChange",
       lua::guarded<lua::command<CarBinding::command, &AnkiCar::cancelLaneChange>>},
      {"uturn", lua::guarded<uturn>},
      {"turn", lua::guarded<turn>},
      {"lights", lua::guarded<lights>},
      {"lightsPattern", lua::guarded<lightsPattern>},
      {"ping", lua::guarded<lua::command<CarBinding::order, &AnkiCar::ping>>},
      {"battery", lua::guarded<lua::command<CarBinding::order, &AnkiCar::requestBattery>>},
      {"version", lua::guarded<lua::command<CarBinding::order, &AnkiCar::requestVersion>>},
      {"disconnect", lua::guarded<lua::command<CarBinding::disconnecting, &AnkiCar::disconnect>>},
      {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kMetatable,
      .name = "car",
      .methods = methods,
      .fields = kFields,
      .events = &carEvents(),
      .slotsOf = [](lua_State* L, int self) -> lua::EventSlots& { return proxyAt(L, self).slots; },
      .unlistened = "onMessage",
      .ownFields = true,
      .label = [](lua_State* L, int self) { return proxyAt(L, self).car->label(); },
  };
  return type;
}
}  // namespace

void CarBinding::registerType(lua_State* L) {
  lua::registerType(L, carType());
}

AnkiCar& CarBinding::check(lua_State* L, int idx) {
  return *proxyAt(L, idx).car;
}

AnkiCar& CarBinding::order(lua_State* L, int idx) {
  Proxy& p = proxyAt(L, idx);
  if (AnkiCar* own = ScriptHost::from(L).driverCar(); own && own != p.car)
    throw LuaError(p.label + " is not this driver's car: a driver commands only its own (" +
                   own->label() + "); the others are there to be read (speed, offset, piece)");
  return *p.car;
}

AnkiCar& CarBinding::disconnecting(lua_State* L, int idx) {
  AnkiCar& car = order(L, idx);
  if (ScriptHost::from(L).driverCar())
    throw LuaError("a driver cannot disconnect its car: the race director keeps the links");
  return car;
}

AnkiCar& CarBinding::command(lua_State* L, int idx) {
  Proxy& p = proxyAt(L, idx);
  order(L, idx);
  if (!p.stopped.empty())
    throw LuaError(p.stopped +
                   "; it takes no command from this script until the script is reloaded (save "
                   "it fixed) or the run restarts");
  return *p.car;
}

void CarBinding::handlerFailed(std::string_view what, std::string_view who,
                               std::string_view message) {
  const HandlerErrorLimit& limit = host_.options().handler_errors;
  if (limit.count <= 0) return;
  // A car's own event handlers and listeners ("onPosition handler", "onPosition listeners",
  // core.lua's "onPosition listener"), and the update of the race library's driver of the car
  // ("update of driver cruiser"), which drivers.run calls on after each error (docs/racing.md):
  // a driver whose update keeps failing would leave its car at its last speed.
  auto endsWith = [&](std::string_view end) {
    return what.size() >= end.size() && what.substr(what.size() - end.size()) == end;
  };
  if (!endsWith(" handler") && !endsWith(" listeners") && !endsWith(" listener") &&
      what.rfind("update of driver ", 0) != 0)
    return;
  Proxy* p = nullptr;
  for (auto& entry : proxies_)
    if (entry.second->label == who) p = entry.second.get();
  // A paused car (Ctrl-Z) or one halted for the end of the run refuses every command: an error
  // that refusal raised in a handler is not the script's fault, and is not counted.
  if (!p || !p->stopped.empty() || p->car->paused() || p->car->halted()) return;
  const double now = host_.loop().seconds();
  auto it = std::find_if(p->failing.begin(), p->failing.end(),
                         [&](const Proxy::Failing& f) { return f.what == what; });
  if (it == p->failing.end()) it = p->failing.insert(it, {std::string(what), now, 0});
  if (now - it->since > limit.window) {
    it->since = now;
    it->count = 0;
  }
  if (++it->count < limit.count) return;
  char window[32];
  std::snprintf(window, sizeof window, "%g", limit.window);
  const std::string_view first = message.substr(0, message.find('\n'));
  p->stopped = p->label + " was stopped: its " + std::string(what) + " failed " +
               std::to_string(it->count) + " times within " + window + " s";
  auto sent = p->car->stop();  // through the vehicle model, as any stop
  log::error("script",
             p->stopped + " (last: " + std::string(first) +
                 "); the race goes on without it, and this script's commands to it are refused: "
                 "fix the handler and save the script (a hot reload drives it again), or run "
                 "with --handler-errors 0 to let a failing car drive on" +
                 (sent ? "" : " (the stop was not sent: " + sent.error() + ")"));
}

void CarBinding::handlerFailedIn(std::string_view where, std::string_view message) {
  for (auto& entry : proxies_) {
    const std::string& label = entry.second->label;
    if (where.size() < label.size() + 4) continue;
    std::string_view end = where.substr(where.size() - label.size() - 4);
    if (end.substr(0, 4) == " of " && end.substr(4) == label)
      return handlerFailed(where.substr(0, where.size() - end.size()), label, message);
  }
}

AnkiCar* CarBinding::test(lua_State* L, int idx) {
  auto** p = lua::test<Proxy*>(L, idx, carType());
  return p ? (*p)->car : nullptr;
}

void CarBinding::bind(AnkiCar& car) {
  if (proxies_.count(&car)) return;
  auto proxy = std::make_unique<Proxy>();
  Proxy& p = *proxy;
  p.car = &car;
  p.label = car.label();
  lua_State* L = L_;
  lua::newBox<Proxy*>(L, carType(), &p);
  p.selfRef = luaL_ref(L, LUA_REGISTRYINDEX);  // cars live as long as the run
  for (auto& t : p.tables) {
    lua_createtable(L, 0, 8);
    t = luaL_ref(L, LUA_REGISTRYINDEX);
  }
  proxies_.emplace(&car, std::move(proxy));

  if (attached_) hookEvents(p);
}

void CarBinding::push(lua_State* L, AnkiCar& car) {
  auto it = proxies_.find(&car);
  if (it == proxies_.end()) {
    bind(car);
    it = proxies_.find(&car);
  }
  lua_rawgeti(L, LUA_REGISTRYINDEX, it->second->selfRef);
}

}  // namespace pitwall
