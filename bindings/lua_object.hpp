#pragma once
// Objects: the one way a binding gives Lua an engine object (a car, a robot, a timer, a seat, the
// script under test). Each type is a TypeSpec (below): one metatable whose methods, read-only
// state fields and `on…` events come from one list each; each object is a full userdata (its
// box) whose table (its uservalue 1) keeps the script's own fields, where the type allows them.
// An object with events owns the Lua functions its events call (EventSlots: the
// handler the script set, and the hub that runs the library's listeners), and every binding
// delivers an event the same way (emit): the listeners first, then the handler, with one table
// (emitArgs: with positional arguments, for the events whose handlers always took them).
#include <lua.hpp>

#include <array>
#include <cctype>
#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
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

// Delivers event e of `source` to the functions that want it, the listeners' hub first, then
// the handler (read after the hub ran: a listener may have removed it), each called as
// fn(object, args…): `push(L)` pushes the arguments and returns how many, once per function
// called (the MindRoad's onLost(robot, reason)). An error in either is reported by the host,
// naming the event and `who`; neither stops the other.
bool pushCallee(const EventSource& source, std::size_t e, bool hub);
void callCallee(const EventSource& source, std::size_t e, bool hub, int nargs);

template <class Push>
void emitArgs(const EventSource& source, std::size_t e, Push&& push) {
  PITWALL_STACK_CHECK(source.host.state(), 0, "an event's delivery (lua::emitArgs)");
  for (bool hub : {true, false})
    if (pushCallee(source, e, hub)) callCallee(source, e, hub, push(source.host.state()));
}

// The same with one table, fn(object, ev), both calls seeing the same one: the reused table at
// `tableRef` (the hot path: `fill` writes only what changed) or, with LUA_NOREF, a fresh one, with
// `time` (the loop's seconds) and what `fill(L)` writes into it (the table on top of the stack).
// Nothing is pushed or built when no function wants the event.
template <class Fill>
void emit(const EventSource& source, std::size_t e, int tableRef, Fill&& fill) {
  PITWALL_STACK_CHECK(source.host.state(), 0, "an event's delivery (lua::emit)");
  ScriptHost& host = source.host;
  lua_State* L = host.state();
  if (tableRef != LUA_NOREF && source.slots.hub(e) == LUA_NOREF) {
    // The hot path (a reused table, the handler alone, no listeners) in one piece, inline
    // (docs/performance.md "Frame → Lua: the plumbing cut, and the floor").
    const int handler = source.slots.handler(e);
    if (handler == LUA_NOREF) return;
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
  if (!source.slots.wanted(e)) return;
  if (tableRef != LUA_NOREF)
    lua_rawgeti(L, LUA_REGISTRYINDEX, tableRef);
  else
    lua_createtable(L, 0, 4);
  lua_pushnumber(L, host.loop().seconds());
  lua_setfield(L, -2, "time");
  fill(L);
  const int table = lua_gettop(L);
  emitArgs(source, e, [table](lua_State* S) {
    lua_pushvalue(S, table);
    return 1;
  });
  lua_pop(L, 1);
}

// What a robot object holds (the Alphabot, the MindRoad): its model, its world, its events'
// handlers, and a registry reference that keeps the object while it is open (its events need
// it; the script may drop it). close() ends its part in the world: the model closed (a
// connected robot is sent its stop), no more events. Safe twice, and from __gc in lua_close. The
// model stays: one of its handlers may be running (a handler that calls robot:close()), and a
// closed model calls none of them again.
template <class Model>
struct Device {
  ScriptHost* host = nullptr;
  std::unique_ptr<Model> model;
  EventSlots slots;
  int selfRef = LUA_NOREF;
  std::string label;  // "alphabot tcp:127.0.0.1:4000"

  void hold(lua_State* L) {  // the object on top of the stack, until close()
    lua_pushvalue(L, -1);
    selfRef = luaL_ref(L, LUA_REGISTRYINDEX);
  }
  void close(lua_State* L) {
    if (model) model->close();
    slots.release(L);
    luaL_unref(L, LUA_REGISTRYINDEX, selfRef);
    selfRef = LUA_NOREF;
  }
  bool closed() const { return selfRef == LUA_NOREF; }
  EventSource source(const EventNames& names) { return {*host, slots, names, selfRef, label}; }
};

// ---- The object idiom: one way for an engine object to reach Lua ----
//
// A type is a TypeSpec, declared with named fields: its metatable's registry key and name, its
// methods, its read-only state fields (name + getter), its events (or none), whether the script
// may keep its own fields on it, and its lifetime hooks. registerType makes its one metatable
// with the generic __index, __newindex, __tostring and __gc below, and locks it
// (bindings/metatables.hpp): no script changes an engine type. Each object is one full userdata,
// its box, holding a T (a pointer to an object the binding owns, or a small value: a timer's
// handle); newBox makes one, check<T> and test<T> read one, with one wording for a wrong value.
// Only this file (and its .cpp) creates metatables or userdata (tests/structure/bindings_test.py).

// One state field: its name, and how its value is pushed for the object at stack index `self`.
// The types generator reads the names (__fields); adding a field is one entry.
struct Field {
  const char* name;
  void (*push)(lua_State* L, int self);
};

struct TypeSpec {
  const char* metatable;       // registry key: "pitwall.car"
  const char* name;            // __name, and how errors name the object: "car"
  const char* what = nullptr;  // how errors name it when not by `name` ("robot")
  const luaL_Reg* methods = nullptr;
  std::span<const Field> fields = {};
  const EventNames* events = nullptr;  // its onX events; none: no events
  // Its event slots (handlers, and the hubs of pitwall.listen); with events only.
  EventSlots& (*slotsOf)(lua_State* L, int self) = nullptr;
  const char* unlistened = nullptr;  // an event that takes no listeners (the car's onMessage)
  bool ownFields = false;            // the script may keep its own fields on it (uservalue 1)
  bool strict = false;  // reading a key it does not have is an error naming what it has
  // Lifetime: how it names itself in messages and prints ("car 1 (skull)"; default: `name`),
  // whether it is closed (no more events: a handler or listener set on it is refused), and what
  // its box does when it goes (garbage, or the world's end: Lua 5.4 runs every finalizer before
  // it frees anything, so the registry is whole there).
  std::string (*label)(lua_State* L, int self) = nullptr;
  bool (*closed)(lua_State* L, int self) = nullptr;
  void (*gc)(lua_State* L, int self) = nullptr;
};

// Registers the type's metatable (once per world).
void registerType(lua_State* L, const TypeSpec& type);

// A plain table given a type of the engine's (pitwall.cars()'s list): its metatable is the one
// under `metatable` in the registry (made once, named `name`, locked) with `index` as __index.
void setTableType(lua_State* L, int idx, const char* metatable, const char* name,
                  lua_CFunction index);
// The table at idx has that type.
bool hasTableType(lua_State* L, int idx, const char* metatable);

// "expected a car, got number": the one sentence for a value that is not an object of `type`.
std::string expectedSentence(lua_State* L, int idx, const TypeSpec& type);

// How errors name an object of `type`: its `what`, else its `name`.
inline const char* whatOf(const TypeSpec& type) {
  return type.what ? type.what : type.name;
}

// A new object of `type` on the stack: its box holds a T made from `args`, its metatable is the
// type's, and with ownFields its own table. A T that is not trivially destructible is the type's
// gc hook's to end (destroyBox).
// (The T is made before the box gets its metatable: a gc hook never meets a T not yet made,
// whatever fails after.)
void* allocateBox(lua_State* L, const TypeSpec& type, std::size_t size);
void finishBox(lua_State* L, const TypeSpec& type);
template <class T, class... Args>
T& newBox(lua_State* L, const TypeSpec& type, Args&&... args) {
  T* made = new (allocateBox(L, type, sizeof(T))) T(std::forward<Args>(args)...);
  finishBox(L, type);
  return *made;
}
// The box of the object of `type` at idx, or nullptr: a full userdata whose metatable is the
// type's — found in the registry by the TypeSpec's address (registerType), not by its name as
// luaL_testudata does (every car field read checks its car: no string lookup).
inline void* testBox(lua_State* L, int idx, const TypeSpec& type) {
  if (lua_type(L, idx) != LUA_TUSERDATA || !lua_getmetatable(L, idx)) return nullptr;
  lua_rawgetp(L, LUA_REGISTRYINDEX, &type);
  const bool same = lua_rawequal(L, -1, -2);
  lua_pop(L, 2);
  return same ? lua_touserdata(L, idx) : nullptr;
}
template <class T>
void destroyBox(lua_State* L, int self, const TypeSpec& type) {
  if (void* p = testBox(L, self, type)) static_cast<T*>(p)->~T();
}

// The object of `type` at idx, or nullptr.
template <class T>
T* test(lua_State* L, int idx, const TypeSpec& type) {
  return static_cast<T*>(testBox(L, idx, type));
}
// The box of the object of `type` at idx; anything else raises expectedSentence.
inline void* checkBox(lua_State* L, int idx, const TypeSpec& type) {
  if (void* p = testBox(L, idx, type)) return p;
  throw LuaError(expectedSentence(L, idx, type));
}
// The object of `type` at idx; anything else raises expectedSentence.
template <class T>
T& check(lua_State* L, int idx, const TypeSpec& type) {
  return *static_cast<T*>(checkBox(L, idx, type));
}

// pitwall._setHub(object, "onX", fn | nil): the function that runs the library's listeners of
// that event (scripts/pitwall/core.lua, pitwall.listen), for an object of any type registered
// with slotsOf: cars, remote cars, robots.
int setHub(lua_State* L);

}  // namespace pitwall::lua
