#pragma once
// What CarBinding keeps per car (private to bindings/car_binding.cpp and car_events.cpp).
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "bindings/car_binding.hpp"
#include "bindings/lua_object.hpp"
#include "engine/core/signal.hpp"

namespace pitwall {

// The car's events by name (bindings/car_binding.cpp).
const lua::EventNames& carEvents();

struct CarBinding::Proxy {
  AnkiCar* car = nullptr;
  std::string label;  // "car 1 (skull)": errors in its handlers name it (made once, at bind)
  int selfRef = LUA_NOREF;
  // The handler of each event and the hub of its listeners (pitwall.listen).
  lua::EventSlots slots;
  std::array<int, kCarEventCount> tables;
  // What the reused onPosition / onTransition tables hold now: a field is written only when its
  // value changed (at a steady speed a position event rewrites just time and location). This is
  // why event tables are read-only for scripts (docs/lua-api.md).
  struct Written {
    std::array<double, 6> value;
    Written() { value.fill(std::numeric_limits<double>::quiet_NaN()); }
  };
  Written position, transition;
  // The binding's slot of the car's connection signal while attached (after the fleet's, which
  // subscribed when the car joined the fleet).
  Subscription connection;
  // A driver world's subscription to the car's messages (the run's world holds its one slot),
  // and every world's to its malformed frames, while attached.
  Subscription messages, malformed;
  // Errors of each failing handler in the current window (CarBinding::handlerFailed), and why
  // the car was stopped for them (empty: it was not; then commands are refused).
  struct Failing {
    std::string what;
    double since = 0;
    int count = 0;
  };
  std::vector<Failing> failing;
  std::string stopped;
  Proxy() { tables.fill(LUA_NOREF); }
};

}  // namespace pitwall
