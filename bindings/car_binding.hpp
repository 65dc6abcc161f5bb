#pragma once
// Cars as Lua objects: one full userdata per car (so `car == car` holds), one metatable, methods
// for the commands, read-only state fields, `on…` event handlers, and any other field the script
// wants to keep on the car. Event tables are reused per car and event (docs/lua-api.md).
#include <lua.hpp>

#include <array>
#include <memory>
#include <string_view>
#include <unordered_map>

#include "bindings/lua_args.hpp"
#include "engine/vehicles/anki_car.hpp"

namespace pitwall {

class ScriptHost;
namespace lua {
class EventNames;
}

// The car's events, in one list: CarEvent::Position is "onPosition", … (docs/lua-api.md).
#define PITWALL_CAR_EVENTS(X) \
  X(Position)                 \
  X(Transition)               \
  X(Intersection)             \
  X(Delocalized)              \
  X(Offset)                   \
  X(Battery)                  \
  X(Version)                  \
  X(Ping)                     \
  X(Status)                   \
  X(Collision) X(Speed) X(LaneChange) X(Recovery) X(Connect) X(Disconnect) X(Malformed) X(Message)

enum class CarEvent { PITWALL_CAR_EVENTS(PITWALL_EVENT_ENUM) Count_ };
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
  // The car at idx for any command (stop, ping, lights, …): in a driver world, refused for any
  // car but the driver's own (HostOptions::driverCar). `disconnecting`: the same for
  // disconnect, which a driver world may not send at all.
  static AnkiCar& order(lua_State* L, int idx);
  static AnkiCar& disconnecting(lua_State* L, int idx);
  // The car at idx for a command that moves it (setSpeed, changeLane, turn, …): refused once
  // the car was stopped for a handler that kept failing (handlerFailed).
  static AnkiCar& command(lua_State* L, int idx);
  // An error was reported in `what` ("onPosition handler", "onPosition listeners") of `who` (a
  // car's label, "car 1 (skull)"; anything else is not a car of this world and is ignored):
  // counted against the world's HostOptions::handler_errors, and the car stopped when that is
  // reached.
  void handlerFailed(std::string_view what, std::string_view who, std::string_view message);
  // The same for an error reported at `where` ("onPosition handler of car 1 (king of hill)"):
  // the car is the one whose label ends it (a name may hold " of " too).
  void handlerFailedIn(std::string_view where, std::string_view message);
  // The car at idx, or nullptr when the value is not a car.
  static AnkiCar* test(lua_State* L, int idx);

  struct Proxy;

 private:
  // Event delivery (car_events.cpp).
  class EventTable;
  void hookEvents(Proxy& p);
  void unhookEvents(Proxy& p);
  void dispatch(Proxy& p, const anki::Message& m);
  void deliverPosition(Proxy& p, const anki::PositionUpdate& pos);
  void dispatchOther(Proxy& p, const anki::Message& m);   // all but position updates
  void deliverMessage(Proxy& p, const anki::Message& m);  // onMessage
  // Delivers event e to the car's listeners and handler (lua::emit), in its reused table.
  template <class Fill>
  void deliver(Proxy& p, CarEvent e, Fill&& fill);

  ScriptHost& host_;
  lua_State* L_;
  const lua::EventNames& names_;  // carEvents(), kept: every event names its source with it
  std::unordered_map<AnkiCar*, std::unique_ptr<Proxy>> proxies_;
  bool attached_ = false;
};

}  // namespace pitwall
