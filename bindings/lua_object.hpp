#pragma once
// Objects with events: the one way a binding gives Lua a device (a car, a remote car, a robot).
// Each type has one metatable whose methods, read-only state fields and `on…` events come from
// one list each (ObjectType); each object is a full userdata whose table (its uservalue 1) keeps
// the script's own fields. An object owns the Lua functions its events call (EventSlots: the
// handler the script set, and the hub that runs the library's listeners), and every binding
// delivers an event the same way (emit): the listeners first, then the handler, with one table
// (emitArgs: with positional arguments, for the events whose handlers always took them).
#include <lua.hpp>

#include <array>
#include <cctype>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "bindings/lua_args.hpp"
#include "bindings/metatables.hpp"
#include "bindings/script_host.hpp"

namespace pitwall::lua {

inline std::string joinNames(std::span<const char* const> names) {
  std::string s;
  for (const char* n : names) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

// The events of one type, from its one list of names ("onPosition", …): an event's index, and
// how errors in its handler and its listeners are named ("onPosition handler").
class EventNames {
 public:
  explicit EventNames(std::span<const char* const> names) : names_(names) {
    if (names.size() > 24) throw std::logic_error("more events than EventSlots::kMaxEvents");
    for (const char* n : names) {
      handler_.push_back(std::string(n) + " handler");
      listeners_.push_back(std::string(n) + " listeners");
    }
  }
  std::span<const char* const> names() const { return names_; }
  std::size_t size() const { return names_.size(); }
  const char* name(std::size_t e) const { return names_[e]; }
  // -1 when `key` is no event of the type.
  int find(std::string_view key) const {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (key == names_[i]) return static_cast<int>(i);
    return -1;
  }
  const char* handlerWhat(std::size_t e) const { return handler_[e].c_str(); }
  const char* listenersWhat(std::size_t e) const { return listeners_[e].c_str(); }

 private:
  std::span<const char* const> names_;
  std::vector<std::string> handler_, listeners_;
};

// The Lua functions one object calls on its events, as registry references the object owns:
// per event, the handler (`object.onX = fn`) and the hub of the library's listeners
// (pitwall.listen, scripts/pitwall/core.lua). release() drops them all: on close, __gc, or when
// the object's world ends.
class EventSlots {
 public:
  static constexpr std::size_t kMaxEvents = 24;  // the most any type has (the car: 17)
  EventSlots() {
    handlers_.fill(LUA_NOREF);
    hubs_.fill(LUA_NOREF);
  }
  EventSlots(const EventSlots&) = delete;
  EventSlots& operator=(const EventSlots&) = delete;

  // The function at stack index `idx` becomes event e's handler (hub); nil removes it.
  void setHandler(lua_State* L, std::size_t e, int idx) { set(L, handlers_[e], idx); }
  void setHub(lua_State* L, std::size_t e, int idx) { set(L, hubs_[e], idx); }
  int handler(std::size_t e) const { return handlers_[e]; }
  int hub(std::size_t e) const { return hubs_[e]; }
  bool wanted(std::size_t e) const { return handlers_[e] != LUA_NOREF || hubs_[e] != LUA_NOREF; }
  void release(lua_State* L) {
    for (auto* refs : {&handlers_, &hubs_})
      for (int& r : *refs) {
        luaL_unref(L, LUA_REGISTRYINDEX, r);
        r = LUA_NOREF;
      }
  }

 private:
  static void set(lua_State* L, int& ref, int idx) {
    idx = lua_absindex(L, idx);
    luaL_unref(L, LUA_REGISTRYINDEX, ref);
    ref = LUA_NOREF;
    if (lua_isfunction(L, idx)) {
      lua_pushvalue(L, idx);
      ref = luaL_ref(L, LUA_REGISTRYINDEX);
    }
  }
  // Inline, not on the heap: the event hot path reads them for every frame.
  std::array<int, kMaxEvents> handlers_, hubs_;
};

// One object as its events see it: its slots and names, its own Lua value (a registry
// reference) and how errors in its handlers name it ("car 1 (skull)").
struct EventSource {
  ScriptHost& host;
  const EventSlots& slots;
  const EventNames& names;
  int selfRef;
  std::string_view who;
};

// Delivers event e of `source`: the listeners' hub, then the handler, each called as
// fn(object, table). The table is the reused one at `tableRef` (the hot path: `fill` writes only
// what changed) or, with LUA_NOREF, a fresh one; either way both calls see the same table, with
// `time` (the loop's seconds) and what `fill(L)` writes into it (the table on top of the stack).
// An error in either is reported by the host, naming the event and `who`; neither stops the
// other. Nothing is pushed or built when no function wants the event.
// emit's two halves, out of line, for every case but the hot one (a reused table and the handler
// alone, no listeners), which emit does inline (docs/performance.md "Frame → Lua: the plumbing cut,
// and the floor"). begin pushes the traceback handler, the first function (the hub if any, else the
// handler), the object and the event table with `time` set, and returns false (nothing pushed) when
// no function wants the event; finish makes the calls.
bool beginEvent(const EventSource& source, std::size_t e, int tableRef);
void finishEvent(const EventSource& source, std::size_t e, int tableRef);

template <class Fill>
void emit(const EventSource& source, std::size_t e, int tableRef, Fill&& fill) {
  PITWALL_STACK_CHECK(source.host.state(), 0, "an event's delivery (lua::emit)");
  if (tableRef != LUA_NOREF && source.slots.hub(e) == LUA_NOREF) {
    // The hot path (a reused table, the handler alone, no listeners) in one piece, inline:
    // what beginEvent and finishEvent do, without their branches and calls.
    const int handler = source.slots.handler(e);
    if (handler == LUA_NOREF) return;
    ScriptHost& host = source.host;
    lua_State* L = host.state();
    lua_pushcfunction(L, traceback);
    lua_rawgeti(L, LUA_REGISTRYINDEX, handler);
    lua_rawgeti(L, LUA_REGISTRYINDEX, source.selfRef);
    lua_rawgeti(L, LUA_REGISTRYINDEX, tableRef);
    lua_pushnumber(L, host.loop().seconds());
    lua_setfield(L, -2, "time");
    fill(L);
    host.callAboveHandler(2, source.names.handlerWhat(e), source.who);
    return;
  }
  if (!beginEvent(source, e, tableRef)) return;
  fill(source.host.state());
  finishEvent(source, e, tableRef);
}

// The same for an event whose functions take positional arguments instead of a table,
// fn(object, args…) (the MindRoad's onLost(robot, reason)): `push(L)` pushes them and returns how
// many. It runs once per function called (the hub, then the handler), so each gets its own.
bool pushCallee(const EventSource& source, std::size_t e, bool hub);
void callCallee(const EventSource& source, std::size_t e, bool hub, int nargs);

template <class Push>
void emitArgs(const EventSource& source, std::size_t e, Push&& push) {
  PITWALL_STACK_CHECK(source.host.state(), 0, "an event's delivery (lua::emitArgs)");
  for (bool hub : {true, false})
    if (pushCallee(source, e, hub)) callCallee(source, e, hub, push(source.host.state()));
}

// A userdata type seen from Lua: one metatable under `metatable` in the registry.
struct ObjectType {
  const char* metatable;  // registry key, "pitwall.car"
  const char* name;       // __name, and how errors name the object: "car"
  const luaL_Reg* methods;
  std::span<const char* const> fields;  // read-only state fields
  const EventNames& events;             // onX handlers
  lua_CFunction index;                  // both get the methods table as upvalue 1
  lua_CFunction newindex;
  lua_CFunction tostring;
  lua_CFunction gc = nullptr;
  const char* what = nullptr;  // how errors name the object when not by `name` ("robot")
  // The object's event slots, for pitwall._setHub (listeners); it may refuse (throw LuaError),
  // e.g. a hub for a closed object. nullptr: the type takes no listeners.
  EventSlots& (*slotsOf)(lua_State* L, int idx) = nullptr;
  const char* unlistened = nullptr;  // an event that takes no listeners (the car's onMessage)
};

// Registers the type's metatable (once): __index and __newindex as closures over the methods
// table, __tostring, __gc, __name, and __methods / __fields / __events, which the REPL completes
// from without calling __index (scripts/pitwall/repl.lua).
inline void registerObjectType(lua_State* L, const ObjectType& type) {
  if (!luaL_newmetatable(L, type.metatable)) {
    lua_pop(L, 1);
    return;
  }
  lua_newtable(L);
  luaL_setfuncs(L, type.methods, 0);
  lua_pushvalue(L, -1);
  lua_setfield(L, -3, "__methods");
  for (auto [names, key] :
       {std::pair{type.fields, "__fields"}, std::pair{type.events.names(), "__events"}}) {
    lua_createtable(L, static_cast<int>(names.size()), 0);
    for (std::size_t i = 0; i < names.size(); ++i) {
      lua_pushstring(L, names[i]);
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    lua_setfield(L, -3, key);
  }
  lua_pushvalue(L, -1);
  lua_pushcclosure(L, type.index, 1);
  lua_setfield(L, -3, "__index");
  lua_pushcclosure(L, type.newindex, 1);
  lua_setfield(L, -2, "__newindex");
  lua_pushcfunction(L, type.tostring);
  lua_setfield(L, -2, "__tostring");
  if (type.gc) {
    lua_pushcfunction(L, type.gc);
    lua_setfield(L, -2, "__gc");
  }
  lua_pushstring(L, type.name);
  lua_setfield(L, -2, "__name");
  // The type itself, for what works on every object type (setHub).
  lua_pushlightuserdata(L, const_cast<ObjectType*>(&type));
  lua_setfield(L, -2, "__objecttype");
  lockMetatable(L, -1);
  lua_pop(L, 1);
}

// __index of an object (1: the object, 2: the key): a method (the methods table is upvalue 1),
// else a state field — `field(key)` pushes it and returns true —, else the object's own table.
template <class Field>
int indexObject(lua_State* L, Field&& field) {
  lua_pushvalue(L, 2);
  if (lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL) return 1;
  lua_pop(L, 1);
  if (lua_type(L, 2) == LUA_TSTRING && field(std::string_view(lua_tostring(L, 2)))) return 1;
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_rawget(L, -2);
  return 1;
}

// __newindex of an object (1: the object, 2: the key, 3: the value): an event's handler is
// checked (a function or nil) and taken into `slots`; a state field, a method, or an onX that is
// no event (a typo would never be called) is refused by name; anything else is the script's own
// field. Every value set is also kept in the object's table, so reading it gives it back.
inline int newindexObject(lua_State* L, const ObjectType& type, EventSlots& slots) {
  if (lua_type(L, 2) == LUA_TSTRING) {
    const std::string key = lua_tostring(L, 2);
    const std::string what = type.what ? type.what : type.name;
    if (int e = type.events.find(key); e >= 0) {
      if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
        throw LuaError(what + "." + key + " must be a function or nil, got " + typeName(L, 3));
      slots.setHandler(L, static_cast<std::size_t>(e), 3);
    } else {
      if (key.size() > 2 && key[0] == 'o' && key[1] == 'n' &&
          std::isupper(static_cast<unsigned char>(key[2])))
        throw LuaError(what + "." + key + " is not an event; the events are " +
                       joinNames(type.events.names()));
      for (const char* f : type.fields)
        if (key == f)
          throw LuaError(what + "." + key + " is read-only (it is the " + what + "'s state)");
      lua_pushvalue(L, 2);
      const bool isMethod = lua_rawget(L, lua_upvalueindex(1)) != LUA_TNIL;
      lua_pop(L, 1);
      if (isMethod) throw LuaError(what + ":" + key + " is a method and cannot be replaced");
    }
  }
  lua_settop(L, 3);
  lua_getiuservalue(L, 1, 1);
  lua_pushvalue(L, 2);
  lua_pushvalue(L, 3);
  lua_rawset(L, 4);
  return 0;
}

// pitwall._setHub(object, "onX", fn | nil): the function that runs the library's listeners of
// that event (scripts/pitwall/core.lua, pitwall.listen), for an object of any type registered
// with slotsOf: cars, remote cars, robots.
int setHub(lua_State* L);

// setHub's work for a type: `except` names an event that takes no listeners (the car's
// onMessage: only through car.onMessage).
inline void setHubOf(lua_State* L, const ObjectType& type, EventSlots& slots,
                     const char* except = nullptr) {
  const EventNames& events = type.events;
  const std::string name = checkString(L, 2, "event name");
  const int e = events.find(name);
  if (e < 0 || (except && name == except))
    throw LuaError(
        "cannot listen to '" + name + "'; the events are " + joinNames(events.names()) +
        (except ? std::string(" (") + except + " only through " + type.name + "." + except + ")"
                : std::string()));
  if (!lua_isnil(L, 3) && !lua_isfunction(L, 3))
    throw LuaError(std::string("a listener hub must be a function or nil, got ") +
                   luaL_typename(L, 3));
  slots.setHub(L, static_cast<std::size_t>(e), 3);
}

}  // namespace pitwall::lua
