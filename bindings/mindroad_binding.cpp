// pitwall.mindroad{host=…, port=…}: a MindRoad robot car as a Lua object (docs/robots.md).
// One full userdata per robot holding its model (engine/vehicles/mindroad_robot.hpp) and its
// events' handlers (lua::EventSlots); a uservalue table keeps the script's own fields, as cars do.
// The object belongs to the Lua world that made it: a registry reference keeps it (and its
// connection) alive until robot:close() or the end of that world (end of the run, a hot reload),
// when __gc closes the link — the robot then gets a stop, or stops by its watchdog.
#include <lua.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bindings/interrupt.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/console.hpp"
#include "engine/core/log.hpp"
#include "engine/core/suggest.hpp"
#include "engine/vehicles/mindroad_robot.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

constexpr const char* kMetatable = "pitwall.mindroad";
constexpr double kConfirmWindow = 5;  // s: shutdown() typed at the REPL must be repeated within it

// The robot's events, from this one list. Their handlers take positional arguments, not a table:
// onContact(robot), onLost(robot, reason) (docs/robots.md).
#define PITWALL_MINDROAD_EVENTS(X) X(Contact) X(Lost)

enum class Event { PITWALL_MINDROAD_EVENTS(PITWALL_EVENT_ENUM) };
constexpr const char* kEvents[] = {PITWALL_MINDROAD_EVENTS(PITWALL_EVENT_NAME)};

struct Robot : lua::Device<MindroadRobot> {
  std::optional<TimePoint> shutdownAsked;
  MindroadOptions options;  // host, port, … stay readable after close()
};

const lua::TypeSpec& robotType();

// The robot at idx: its box holds the Robot itself (its gc ends it).
Robot& robotAt(lua_State* L, int idx) {
  return lua::check<Robot>(L, idx, robotType());
}

bool isOpen(const Robot& r) {
  return r.model && r.model->phase() != MindroadRobot::Phase::Closed;
}

// The robot's model, which refuses every command once it is closed (its one check of that;
// events on a closed robot are refused by the type, TypeSpec::closed).
MindroadRobot& open(lua_State* L, int idx) {
  return *robotAt(L, idx).model;
}

const lua::EventNames& events() {
  static const lua::EventNames names(kEvents);
  return names;
}

// Calls the listeners and the handler of `e` as fn(robot, args…); `push` pushes the arguments and
// returns how many.
template <class Push>
void deliver(Robot& r, Event e, Push&& push) {
  if (!r.closed()) lua::emitArgs(r.source(events()), static_cast<std::size_t>(e), push);
}

// ---- methods ----
int steer(lua_State* L) {
  return lua::raiseIfRefused(open(L, 1).steer(lua::checkRounded(L, 2, "steer x (forward/backward)"),
                                              lua::checkRounded(L, 3, "steer y (right/left)")));
}

int click(lua_State* L) {
  return lua::raiseIfRefused(
      open(L, 1).click(lua::checkRounded(L, 2, "click x"), lua::checkRounded(L, 3, "click y")));
}

constexpr std::pair<const char*, int> kButtons[] = {
    {"manual", 0}, {"automatic", 1}, {"sensitivity-up", 2}, {"sensitivity-down", 3}};
std::uint8_t buttonAt(lua_State* L, int idx) {
  const int b = lua::checkName(L, idx, "button", kButtons);
  return static_cast<std::uint8_t>(*mindroad::buttonFromName(kButtons[b].first));
}

// buttons("automatic"): the byte is that button's id (seed table 2); buttons{"manual",
// "sensitivity-up"}: a bit mask, bit n for button n (seed §5.2); buttons(0x05): the raw byte.
int buttons(lua_State* L) {
  auto& c = open(L, 1);
  long long raw = 0;
  if (lua_type(L, 2) == LUA_TSTRING) {
    raw = buttonAt(L, 2);
  } else if (lua_istable(L, 2)) {
    const auto n = luaL_len(L, 2);
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_geti(L, 2, i);
      if (lua_type(L, -1) != LUA_TSTRING)
        throw LuaError("buttons{…} takes button names, got " + lua::typeName(L, -1) + " at " +
                       std::to_string(i));
      raw |= 1 << buttonAt(L, -1);
      lua_pop(L, 1);
    }
  } else if (lua_type(L, 2) == LUA_TNUMBER) {
    raw = lua::checkInteger(L, 2, "buttons byte");
  } else {
    throw LuaError("buttons takes a button name, a list of names or a byte 0..255, got " +
                   lua::typeName(L, 2));
  }
  return lua::raiseIfRefused(c.buttons(raw));
}

int pictureMode(lua_State* L) {
  return lua::raiseIfRefused(open(L, 1).pictureMode(lua::checkString(L, 2, "picture mode")));
}

// Turns the robot off. Typed at the REPL it asks first: the first call prints a warning, a
// second one within 5 s sends it. Returns true when sent, false when waiting for confirmation.
int shutdown(lua_State* L) {
  Robot& r = robotAt(L, 1);
  auto& c = open(L, 1);
  if (interrupt::inConsole()) {
    const TimePoint now = r.host->loop().now();
    if (!r.shutdownAsked || now - *r.shutdownAsked > fromSeconds(kConfirmWindow)) {
      if (!c.connected()) lua::raiseIfRefused(c.shutdown());  // the same error as without asking
      r.shutdownAsked = now;
      console::write(r.label +
                     ": shutdown() turns the robot OFF (it needs a person to turn it on again). "
                     "Call shutdown() again within 5 s to confirm.\n");
      lua_pushboolean(L, 0);
      return 1;
    }
    r.shutdownAsked.reset();
  }
  lua::raiseIfRefused(c.shutdown());
  lua_pushboolean(L, 1);
  return 1;
}

int close(lua_State* L) {
  robotAt(L, 1).close(L);
  return 0;
}

std::string robotLabel(lua_State* L, int self) {
  Robot& r = robotAt(L, self);
  return r.label + " (" + (isOpen(r) ? r.model->phaseName() : "closed") + ")";
}

// ---- state fields: one entry each ----
const MindroadOptions& optionsAt(lua_State* L, int self) {
  return robotAt(L, self).options;
}

const lua::Field kFields[] = {
    {"connected",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       lua_pushboolean(L, isOpen(r) && r.model->connected());
     }},
    {"host", [](lua_State* L, int self) { lua_pushstring(L, optionsAt(L, self).host.c_str()); }},
    {"port", [](lua_State* L, int self) { lua_pushinteger(L, optionsAt(L, self).port); }},
    {"udp", [](lua_State* L, int self) { lua_pushboolean(L, optionsAt(L, self).udp); }},
    {"watchdog", [](lua_State* L, int self) { lua_pushnumber(L, optionsAt(L, self).watchdog); }},
    {"phase",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       lua_pushstring(L, isOpen(r) ? r.model->phaseName().c_str() : "closed");
     }},
    {"lastError",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       if (isOpen(r) && !r.model->lastError().empty())
         lua_pushstring(L, r.model->lastError().c_str());
       else
         lua_pushnil(L);
     }},
    {"contacts",
     [](lua_State* L, int self) {
       Robot& r = robotAt(L, self);
       lua_pushinteger(L, isOpen(r) ? static_cast<lua_Integer>(r.model->contacts()) : 0);
     }},
};

const lua::TypeSpec& robotType() {
  static const luaL_Reg methods[] = {
      {"steer", lua::guarded<steer>},
      {"click", lua::guarded<click>},
      {"buttons", lua::guarded<buttons>},
      {"pictureMode", lua::guarded<pictureMode>},
      {"stop", lua::guarded<lua::command<open, &MindroadRobot::stop>>},
      {"ping", lua::guarded<lua::command<open, &MindroadRobot::ping>>},
      {"shutdown", lua::guarded<shutdown>},
      {"close", lua::guarded<close>},
      {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kMetatable,
      .name = "mindroad",
      .what = "robot",
      .methods = methods,
      .fields = kFields,
      .events = &events(),
      .slotsOf = [](lua_State* L, int self) -> lua::EventSlots& { return robotAt(L, self).slots; },
      .ownFields = true,
      .label = robotLabel,
      .closed = [](lua_State* L, int self) { return !isOpen(robotAt(L, self)); },
      // The registry is still whole here, even in lua_close: Lua 5.4 runs every finalizer
      // before it frees anything (luaC_freeallobjects).
      .gc =
          [](lua_State* L, int self) {
            robotAt(L, self).close(L);
            lua::destroyBox<Robot>(L, self, robotType());
          },
  };
  return type;
}

// Reads the options table at idx into o; unknown keys are refused (a typo would silently fall
// back to a default).
MindroadOptions readOptions(lua_State* L, int idx) {
  static constexpr std::array<const char*, 5> kOptions = {"host", "port", "udp", "watchdog",
                                                          "contactTimeout"};
  lua::Options options(L, idx, "pitwall.mindroad", kOptions, "host=, port=, udp=, watchdog=");
  MindroadOptions o;
  if (auto host = options.string("host")) {
    if (host->empty()) throw LuaError("host must not be empty");
    o.host = *host;
  }
  if (auto port = options.integer("port", 1, 65535)) o.port = static_cast<std::uint16_t>(*port);
  if (auto udp = options.boolean("udp")) o.udp = *udp;
  if (auto watchdog = options.number("watchdog", 0.03, 60, "s")) o.watchdog = *watchdog;
  if (auto timeout = options.number("contactTimeout", 0.1, 600, "s")) o.contactTimeout = *timeout;
  return o;
}

int newRobot(lua_State* L) {
  MindroadOptions options = readOptions(L, 1);
  ScriptHost& host = ScriptHost::from(L);
  Robot* r = &lua::newBox<Robot>(L, robotType());
  r->host = &host;
  r->options = options;
  r->model =
      std::make_unique<MindroadRobot>(host.loop(), makeMindroadLink(host.loop(), options), options);
  r->label = "mindroad " + r->model->address();
  r->hold(L);
  r->model->onContact = [r] { deliver(*r, Event::Contact, [](lua_State*) { return 0; }); };
  r->model->onLost = [r](const std::string& reason) {
    deliver(*r, Event::Lost, [&reason](lua_State* S) {
      lua_pushlstring(S, reason.data(), reason.size());
      return 1;
    });
  };
  if (host.loop().clockKind() == ClockKind::Virtual)
    log::warn("mindroad", r->label +
                              ": virtual time (--fast, tests) races past the timeouts of a real "
                              "socket; a robot needs a real-time run");
  return 1;
}

}  // namespace

void openMindroadModule(ScriptHost& host) {
  lua_State* L = host.state();
  lua::registerType(L, robotType());
  lua_getglobal(L, "pitwall");
  lua_pushcfunction(L, lua::guarded<newRobot>);
  lua_setfield(L, -2, "mindroad");
  lua_pop(L, 1);
}

}  // namespace pitwall
