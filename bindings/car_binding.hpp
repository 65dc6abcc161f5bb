#pragma once
// Cars as Lua objects: one full userdata per car (so `car == car` holds), one metatable, methods
// for the commands, read-only state fields, `on…` event handlers, and any other field the script
// wants to keep on the car. Event tables are reused per car and event (docs/lua-api.md).
#include <lua.hpp>

#include <array>
#include <memory>
#include <unordered_map>

#include "engine/vehicles/anki_car.hpp"

namespace pitwall {

class ScriptHost;

enum class CarEvent {
  Position,
  Transition,
  Intersection,
  Delocalized,
  Offset,
  Battery,
  Version,
  Ping,
  Status,
  Collision,
  Speed,
  LaneChange,
  Recovery,
  Connect,
  Disconnect,
  Malformed,
  Message,
  Count_
};
inline constexpr std::size_t kCarEventCount = static_cast<std::size_t>(CarEvent::Count_);

class CarBinding {
 public:
  explicit CarBinding(ScriptHost& host);
  ~CarBinding();

  void registerType(lua_State* L);
  // Makes the Lua object of a car (once); while attached, routes its events into Lua.
  void bind(AnkiCar& car);
  // Routes the events of every bound car (and of cars bound later) into this Lua world, or
  // gives them back to whatever watched them before. A hot reload starts the new version
  // detached and attaches it only once it has started (docs/hot-reload.md).
  void attach();
  void detach();
  bool attached() const { return attached_; }
  void push(lua_State* L, AnkiCar& car);
  static AnkiCar& check(lua_State* L, int idx);
  // The car at idx, or nullptr when the value is not a car.
  static AnkiCar* test(lua_State* L, int idx);
  // pitwall._setHub(car, "onPosition", fn | nil): the function that runs the library's
  // listeners of that event (scripts/pitwall/core.lua, pitwall.listen).
  static int setHub(lua_State* L);

  struct Proxy;

 private:
  // Event delivery (car_events.cpp).
  class EventTable;
  void hookEvents(Proxy& p);
  void unhookEvents(Proxy& p);
  void dispatch(Proxy& p, const anki::Message& m);
  // Pushes traceback handler, handler, car and the reused event table (time set); false, and
  // nothing pushed, when the car has no handler for `e`.
  bool begin(Proxy& p, CarEvent e);
  void finish(Proxy& p, CarEvent e);

  ScriptHost& host_;
  lua_State* L_;
  std::unordered_map<AnkiCar*, std::unique_ptr<Proxy>> proxies_;
  bool attached_ = false;
};

}  // namespace pitwall
