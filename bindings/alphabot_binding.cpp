// pitwall.alphabot{host=…, port=…} / {ble=ADDR}: an Alphabot robot as a Lua object
// (docs/robots.md) over its model (engine/vehicles/alphabot.hpp). One full userdata per robot,
// owning the model and its events' handlers (lua::EventSlots); the world keeps it in the registry
// until robot:close() or the end of the world (lua_close runs __gc: the robot is sent a stop and
// its link is closed, so nothing reaches a Lua state that is gone).
#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bindings/lua_object.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/core/overload.hpp"
#include "engine/core/suggest.hpp"
#include "engine/protocol/alphabot/command_text.hpp"
#include "engine/protocol/alphabot/toggles.hpp"
#include "engine/vehicles/alphabot.hpp"

namespace pitwall {

namespace ab = alphabot;
using lua::LuaError;

namespace {

constexpr const char* kMetatable = "pitwall.alphabot";

// The robot's events, from this one list: each handler is called as fn(robot, ev), ev.time
// being the loop's seconds.
// clang-format off
#define PITWALL_ALPHABOT_EVENTS(X)                                                 \
  X(Distance) X(Position) X(Compass) X(Obstacle) X(Path) X(Ping) X(Connect)        \
  X(Disconnect) X(Malformed) X(MapSize) X(Anchor) X(Calibrated)
// clang-format on

enum class Event { PITWALL_ALPHABOT_EVENTS(PITWALL_EVENT_ENUM) };
constexpr const char* kEventNames[] = {PITWALL_ALPHABOT_EVENTS(PITWALL_EVENT_NAME)};

using Robot = lua::Device<Alphabot>;

const lua::TypeSpec& robotType();

// The robot at idx: its box holds the Robot itself (its gc ends it).
Robot& robotAt(lua_State* L, int idx) {
  return lua::check<Robot>(L, idx, robotType());
}

// ---- events ----

const lua::EventNames& events() {
  static const lua::EventNames names(kEventNames);
  return names;
}

// Calls robot.onX(robot, ev) with a fresh ev filled by `fill` (the table on top of the stack).
template <class Fill>
void deliver(Robot& r, Event e, Fill&& fill) {
  if (!r.closed()) lua::emit(r.source(events()), static_cast<std::size_t>(e), LUA_NOREF, fill);
}

void pushWaypoints(lua_State* L, const std::vector<ab::Waypoint>& waypoints) {
  lua_createtable(L, static_cast<int>(waypoints.size()), 0);
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    lua_createtable(L, 0, 2);
    lua::setInteger(L, "x", waypoints[i].x);
    lua::setInteger(L, "y", waypoints[i].y);
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
}

void received(Robot& r, const ab::Response& response) {
  std::visit(
      Overload{
          [&](const ab::Distance& d) {
            deliver(r, Event::Distance, [&](lua_State* L) {
              lua::setInteger(L, "degree", d.degree);
              lua::setInteger(L, "distance", d.distance);
            });
          },
          [&](const ab::Position& p) {
            deliver(r, Event::Position, [&](lua_State* L) {
              lua::setInteger(L, "x", p.x);
              lua::setInteger(L, "y", p.y);
            });
          },
          [&](const ab::Path& p) {
            deliver(r, Event::Path, [&](lua_State* L) {
              pushWaypoints(L, p.waypoints);
              lua_setfield(L, -2, "waypoints");
              lua::setBoolean(L, "reachable", !p.waypoints.empty());
            });
          },
          [&](const ab::Compass& c) {
            deliver(r, Event::Compass,
                    [&](lua_State* L) { lua::setInteger(L, "degree", c.degree); });
          },
          [&](const ab::PingReply&) {
            double rtt = r.model->state().lastPing.value_or(0);
            deliver(r, Event::Ping, [&](lua_State* L) { lua::setNumber(L, "rtt", rtt); });
          },
          [&](const ab::ObstacleRegistered& o) {
            deliver(r, Event::Obstacle, [&](lua_State* L) {
              lua::setInteger(L, "id", o.id);
              lua::setInteger(L, "x", o.x);
              lua::setInteger(L, "y", o.y);
              lua::setInteger(L, "width", o.width);
              lua::setInteger(L, "height", o.height);
            });
          },
          [&](const ab::MapSize& m) {
            deliver(r, Event::MapSize, [&](lua_State* L) {
              lua::setInteger(L, "length", m.length);
              lua::setInteger(L, "width", m.width);
            });
          },
          [&](const ab::AnchorPosition& a) {
            deliver(r, Event::Anchor, [&](lua_State* L) {
              lua::setInteger(L, "id", a.id);
              lua::setInteger(L, "x", a.x);
              lua::setInteger(L, "y", a.y);
            });
          },
          [&](const ab::CalibrationFinished&) { deliver(r, Event::Calibrated, [](lua_State*) {}); },
      },
      response);
}

void hook(Robot& r) {
  Alphabot& m = *r.model;
  m.onResponse = [&r](const ab::Response& response) { received(r, response); };
  m.onConnection = [&r](bool up, const std::string& reason) {
    if (up) return deliver(r, Event::Connect, [](lua_State*) {});
    // onDisconnect follows a connection, not a failed attempt
    if (!r.model->state().everConnected) return;
    deliver(r, Event::Disconnect, [&](lua_State* L) { lua::setString(L, "reason", reason); });
  };
  m.onMalformed = [&r](const std::string& error) {
    deliver(r, Event::Malformed, [&](lua_State* L) { lua::setString(L, "error", error); });
  };
}

// ---- commands ----

Alphabot& model(lua_State* L, int idx) {
  return *robotAt(L, idx).model;
}

int drive(lua_State* L) {
  return lua::raiseIfRefused(
      model(L, 1).drive(lua::checkRounded(L, 2, "speed"), lua::checkRounded(L, 3, "steer")));
}
int measureDistance(lua_State* L) {
  return lua::raiseIfRefused(model(L, 1).measureDistance(lua::checkRounded(L, 2, "degree")));
}
int set(lua_State* L) {
  Robot& r = robotAt(L, 1);
  static const std::vector<const char*> kNames = [] {
    std::vector<const char*> names;
    for (const auto& bit : ab::toggleBits()) names.push_back(bit.name);
    return names;
  }();
  if (!lua_istable(L, 2))
    throw LuaError("set takes a table of toggles, e.g. {collisionAvoidance = true}; names: " +
                   ab::toggleNames());
  lua::Options toggles(L, 2, "set", kNames, "collisionAvoidance = true, …");
  // The robot takes the whole field: every bit not named keeps its last value.
  ab::Toggles next = r.model->state().toggles;
  for (const auto& bit : ab::toggleBits())
    if (auto on = toggles.boolean(bit.name)) ab::setBit(next, bit, *on);
  return lua::raiseIfRefused(r.model->setToggles(next));
}
int setAnchor(lua_State* L) {
  return lua::raiseIfRefused(model(L, 1).setAnchor(lua::checkInteger(L, 2, "anchor id"),
                                                   lua::checkRounded(L, 3, "x (cm)"),
                                                   lua::checkRounded(L, 4, "y (cm)")));
}
int navigateTo(lua_State* L) {
  return lua::raiseIfRefused(
      model(L, 1).navigateTo(lua::checkRounded(L, 2, "x (cm)"), lua::checkRounded(L, 3, "y (cm)")));
}
int addObstacle(lua_State* L) {
  return lua::raiseIfRefused(model(L, 1).addObstacle(
      lua::checkRounded(L, 2, "x (cm)"), lua::checkRounded(L, 3, "y (cm)"),
      lua::checkRounded(L, 4, "width (cm)"), lua::checkRounded(L, 5, "height (cm)")));
}
int removeObstacle(lua_State* L) {
  auto& m = model(L, 1);
  if (lua_isnoneornil(L, 3))
    return lua::raiseIfRefused(m.removeObstacle(lua::checkInteger(L, 2, "obstacle id")));
  return lua::raiseIfRefused(
      m.removeObstacleAt(lua::checkRounded(L, 2, "x (cm)"), lua::checkRounded(L, 3, "y (cm)")));
}
int close(lua_State* L) {
  robotAt(L, 1).close(L);
  return 0;
}

// ---- fields and metamethods ----

const AlphabotState& stateAt(lua_State* L, int self) {
  return robotAt(L, self).model->state();
}
void pushOptional(lua_State* L, const std::optional<int>& v) {
  v ? lua_pushinteger(L, *v) : lua_pushnil(L);
}

const lua::Field kFields[] = {
    {"connected",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       lua_pushboolean(L, !r.closed() && r.model->connected());
     }},
    {"x", [](lua_State* L, int self) { pushOptional(L, stateAt(L, self).x); }},
    {"y", [](lua_State* L, int self) { pushOptional(L, stateAt(L, self).y); }},
    {"heading", [](lua_State* L, int self) { pushOptional(L, stateAt(L, self).heading); }},
    {"address",
     [](lua_State* L, int self) { lua_pushstring(L, robotAt(L, self).model->address().c_str()); }},
    {"lastPing",
     [](lua_State* L, int self) {
       const auto& ping = stateAt(L, self).lastPing;
       ping ? lua_pushnumber(L, *ping) : lua_pushnil(L);
     }},
    {"pings",
     [](lua_State* L, int self) {
       lua_pushinteger(L, static_cast<lua_Integer>(stateAt(L, self).pings));
     }},
    {"lastError",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       const std::string e = r.closed() ? r.label + " is closed" : r.model->lastError();
       e.empty() ? lua_pushnil(L) : (void)lua_pushstring(L, e.c_str());
     }},
    {"toggles",
     [](lua_State* L, int self) {
       const AlphabotState& st = stateAt(L, self);
       lua_createtable(L, 0, static_cast<int>(ab::toggleBits().size()));
       for (const auto& bit : ab::toggleBits())
         lua::setBoolean(L, bit.name, ab::isSet(st.toggles, bit));
     }},
    {"malformed",
     [](lua_State* L, int self) {
       lua_pushinteger(L, static_cast<lua_Integer>(stateAt(L, self).malformed));
     }},
    {"path", [](lua_State* L, int self) { pushWaypoints(L, stateAt(L, self).path); }},
};

// ---- pitwall.alphabot{…} ----

int newRobot(lua_State* L) {
  if (!lua_istable(L, 1))
    throw LuaError(
        "pitwall.alphabot takes a table: {host = \"127.0.0.1\", port = 4000} or "
        "{ble = \"AA:BB:CC:DD:EE:FF\"}");
  static constexpr std::array<const char*, 4> kOptions = {"host", "port", "connectTimeout", "ble"};
  lua::Options read(L, 1, "pitwall.alphabot", kOptions, "host=, port= or ble=");
  const std::string host = read.string("host").value_or("");
  const std::string ble = read.string("ble").value_or("");
  const long long port = read.integer("port", 1, 65535).value_or(0);
  const double timeout = read.number("connectTimeout", 0.001, 60, "s").value_or(3.0);
  if (host.empty() == ble.empty())
    throw LuaError("pitwall.alphabot needs either host (and port) for WLAN or ble for Bluetooth");
  ScriptHost& scriptHost = ScriptHost::from(L);
  Loop& loop = scriptHost.loop();
  std::unique_ptr<Link> link;
  AlphabotOptions options;
  if (!host.empty()) {
    if (port == 0) throw LuaError("pitwall.alphabot{host=…} needs a port (1..65535)");
    if (loop.clockKind() == ClockKind::Virtual)
      throw LuaError(
          "pitwall.alphabot{host=…} talks to a robot over the network and needs the real clock: "
          "run without --fast (not in `pitwall test`)");
    link = makeAlphabotTcpLink(loop, host, static_cast<std::uint16_t>(port), timeout);
  } else {
    std::string error;
    options.wire = AlphabotOptions::Wire::Ble;
    link = makeAlphabotBleLink(loop, ble, GattLinkOptions{}, error);
    if (!link) throw LuaError("pitwall.alphabot{ble=\"" + ble + "\"}: " + error);
  }

  auto model = std::make_unique<Alphabot>(loop, std::move(link), options);
  Robot& robot = lua::newBox<Robot>(L, robotType());
  robot.host = &scriptHost;
  robot.model = std::move(model);
  robot.label = robot.model->label();
  robot.hold(L);  // lives until close() or the world's end
  hook(robot);
  return 1;
}

const lua::TypeSpec& robotType() {
  static const luaL_Reg methods[] = {
      {"drive", lua::guarded<drive>},
      {"stop", lua::guarded<lua::command<model, &Alphabot::stop>>},
      {"measureDistance", lua::guarded<measureDistance>},
      {"calibrateSteering", lua::guarded<lua::command<model, &Alphabot::calibrateSteering>>},
      {"calibrateCompass", lua::guarded<lua::command<model, &Alphabot::calibrateCompass>>},
      {"set", lua::guarded<set>},
      {"ping", lua::guarded<lua::command<model, &Alphabot::ping>>},
      {"setAnchor", lua::guarded<setAnchor>},
      {"navigateTo", lua::guarded<navigateTo>},
      {"addObstacle", lua::guarded<addObstacle>},
      {"removeObstacle", lua::guarded<removeObstacle>},
      {"clearObstacles", lua::guarded<lua::command<model, &Alphabot::clearObstacles>>},
      {"close", lua::guarded<close>},
      {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kMetatable,
      .name = "alphabot",
      .methods = methods,
      .fields = kFields,
      .events = &events(),
      .slotsOf = [](lua_State* L, int self) -> lua::EventSlots& { return robotAt(L, self).slots; },
      .ownFields = true,
      .label = [](lua_State* L, int self) { return robotAt(L, self).label; },
      .closed = [](lua_State* L, int self) { return robotAt(L, self).closed(); },
      .gc =
          [](lua_State* L, int self) {
            robotAt(L, self).close(L);
            lua::destroyBox<Robot>(L, self, robotType());
          },
  };
  return type;
}

}  // namespace

// robot:ping([timeout]) in a task waits for the reply and returns the round-trip time in seconds
// (nil and a message after `timeout`, 2 s by default); anywhere else (a callback, the REPL) it
// only sends, and the time arrives in onPing and robot.lastPing.
constexpr const char* kPingWaits = R"(
local methods = ...
local send = methods.ping
methods.ping = function(robot, timeout)
  local before = robot.pings
  send(robot)
  if not coroutine.isyieldable() then return nil end
  timeout = timeout or 2
  if pitwall.waitUntil(function() return robot.pings > before end, timeout, 0.001) then
    return robot.lastPing
  end
  return nil, string.format("%s: no ping reply within %g s", tostring(robot), timeout)
end)";

void openAlphabotModule(ScriptHost& host) {
  lua_State* L = host.state();
  lua::registerType(L, robotType());
  luaL_getmetatable(L, kMetatable);
  lua_getfield(L, -1, "__methods");
  if (luaL_loadbufferx(L, kPingWaits, std::strlen(kPingWaits), "=alphabot ping", "t") != LUA_OK)
    throw std::logic_error(lua_tostring(L, -1));
  lua_insert(L, -2);
  lua_call(L, 1, 0);
  lua_pop(L, 1);
  lua_getglobal(L, "pitwall");
  lua_pushcfunction(L, lua::guarded<newRobot>);
  lua_setfield(L, -2, "alphabot");
  lua_pop(L, 1);
}

}  // namespace pitwall
