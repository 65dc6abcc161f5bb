// Events from cars into Lua: the hot path of every run (docs/performance.md).
//
// Each car has one reused table per event kind. Filling it is most of the cost of an event, so
// the position and transition tables get only the fields whose value changed, and the traceback
// handler is pushed in place under the function instead of rotated in and out. (Keeping the field
// names as ready-made Lua strings and using lua_rawset was measured slower than lua_setfield,
// whose key lookup Lua caches: docs/performance.md.)
#include <cstdio>

#include "bindings/car_binding.hpp"
#include "bindings/car_proxy.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/overload.hpp"
#include "engine/protocol/anki/message_json.hpp"

namespace pitwall {

using namespace anki;

namespace {

enum Key {
  kTime,
  kPiece,
  kLocation,
  kOffset,
  kSpeed,
  kReverse,
  kLeftWheel,
  kRightWheel,
  kDrift,
  kUphill,
  kDownhill,
  kCode,
  kExiting,
  kSinceTransition,
  kSinceIntersection,
  kLaneChangeId,
  kMillivolts,
  kLow,
  kFull,
  kCharging,
  kVersion,
  kRtt,
  kOnTrack,
  kOnCharger,
  kLowBattery,
  kFullyCharged,
  kSide,
  kWhere,
  kDesired,
  kAccel,
  kActual,
  kCurrent,
  kTarget,
  kHSpeed,
  kVSpeed,
  kSucceeded,
  kReason,
  kError,
  kHex,
  kKeyCount
};

constexpr std::array<const char*, kKeyCount> kKeyNames = {
    "time",         "piece",           "location",
    "offset",       "speed",           "reverse",
    "leftWheel",    "rightWheel",      "drift",
    "uphill",       "downhill",        "code",
    "exiting",      "sinceTransition", "sinceIntersection",
    "laneChangeId", "millivolts",      "low",
    "full",         "charging",        "version",
    "rtt",          "onTrack",         "onCharger",
    "lowBattery",   "fullyCharged",    "side",
    "where",        "desired",         "accel",
    "actual",       "current",         "target",
    "hSpeed",       "vSpeed",          "succeeded",
    "reason",       "error",           "hex"};

}  // namespace

// Sets fields of the event table on top of the stack.
class CarBinding::EventTable {
 public:
  explicit EventTable(lua_State* L) : L_(L) {}

  void integer(Key k, lua_Integer v) {
    lua_pushinteger(L_, v);
    lua_setfield(L_, -2, kKeyNames[k]);
  }
  void number(Key k, double v) {
    lua_pushnumber(L_, v);
    lua_setfield(L_, -2, kKeyNames[k]);
  }
  void boolean(Key k, bool v) {
    lua_pushboolean(L_, v);
    lua_setfield(L_, -2, kKeyNames[k]);
  }
  void string(Key k, std::string_view v) {
    lua_pushlstring(L_, v.data(), v.size());
    lua_setfield(L_, -2, kKeyNames[k]);
  }
  // Only when `v` differs from what slot `i` of `w` says the table holds.
  void changed(Proxy::Written& w, int i, Key k, double v) {
    if (w.value[i] == v) return;
    w.value[i] = v;
    number(k, v);
  }
  void changedInteger(Proxy::Written& w, int i, Key k, lua_Integer v) {
    if (w.value[i] == static_cast<double>(v)) return;
    w.value[i] = static_cast<double>(v);
    integer(k, v);
  }
  void changedBoolean(Proxy::Written& w, int i, Key k, bool v) {
    if (w.value[i] == (v ? 1.0 : 0.0)) return;
    w.value[i] = v ? 1.0 : 0.0;
    boolean(k, v);
  }

 private:
  lua_State* L_;
};

template <class Fill>
void CarBinding::deliver(Proxy& p, CarEvent e, Fill&& fill) {
  const auto i = static_cast<std::size_t>(e);
  lua::emit({host_, p.slots, names_, p.selfRef, p.label}, i, p.tables[i], [&](lua_State* L) {
    EventTable t(L);
    fill(t);
  });
}

void CarBinding::hookEvents(Proxy& p) {
  AnkiCar& car = *p.car;
  // The run's world holds the car's one message slot (the hot path); a driver world listens
  if (host_.driverCar())
    p.messages = car.messages.connect([this, &p](const Message& m) { dispatch(p, m); });
  else
    car.onMessage = [this, &p](const Message& m) { dispatch(p, m); };
  // The fleet watches connections too (a car joins the run on its first one), and hears each
  // before the binding: it subscribed first.
  p.connection = car.connectionChanged.connect([this, &p](bool up, const std::string& reason) {
    if (up)
      deliver(p, CarEvent::Connect, [](EventTable&) {});
    else
      deliver(p, CarEvent::Disconnect, [&](EventTable& t) { t.string(kReason, reason); });
  });
  p.malformed =
      car.malformed.connect([this, &p](const DecodeError& e, std::span<const std::uint8_t> bytes) {
        std::string what = e.message();  // logged by the car, a count at a time in a flood
        deliver(p, CarEvent::Malformed, [&](EventTable& t) {
          t.string(kError, what);
          t.string(kHex, toHex(bytes));
        });
      });
}

void CarBinding::unhookEvents(Proxy& p) {
  if (host_.driverCar())
    p.messages.disconnect();
  else
    p.car->onMessage = nullptr;
  p.connection.disconnect();
  p.malformed.disconnect();
}

void CarBinding::dispatch(Proxy& p, const Message& m) {
  if (const auto* pos = std::get_if<PositionUpdate>(&m)) {  // most frames: no visit
    deliverPosition(p, *pos);
  } else {
    dispatchOther(p, m);
  }
  // onMessage sees every message as a fresh table built from its JSON form (for debugging).
  if (p.slots.handler(static_cast<std::size_t>(CarEvent::Message)) != LUA_NOREF)
    deliverMessage(p, m);
}

// The hot path of every run, flattened: the delivery and the protected call inline in one piece.
[[gnu::flatten]] void CarBinding::deliverPosition(Proxy& p, const PositionUpdate& pos) {
  deliver(p, CarEvent::Position, [&](EventTable& t) {
    Proxy::Written& w = p.position;
    t.changedInteger(w, 0, kLocation, pos.location_id);
    t.changedInteger(w, 1, kPiece, pos.piece_id);
    t.changedInteger(w, 2, kSpeed, pos.speed_mm_s);
    t.changed(w, 3, kOffset, pos.offset_mm);
    t.changedBoolean(w, 4, kReverse, (pos.parsing_flags & 0x20) != 0);
  });
}

void CarBinding::dispatchOther(Proxy& p, const Message& m) {
  std::visit(
      Overload{
          [&](const TransitionUpdate& tr) {
            deliver(p, CarEvent::Transition, [&](EventTable& t) {
              Proxy::Written& w = p.transition;
              t.changed(w, 0, kOffset, tr.offset_mm);
              t.changedInteger(w, 1, kLeftWheel, tr.left_wheel_distance_cm);
              t.changedInteger(w, 2, kRightWheel, tr.right_wheel_distance_cm);
              t.changedInteger(w, 3, kDrift, tr.average_follow_line_drift_px);
              t.changedInteger(w, 4, kUphill, tr.uphill_counter);
              t.changedInteger(w, 5, kDownhill, tr.downhill_counter);
            });
          },
          [&](const IntersectionUpdate& i) {
            deliver(p, CarEvent::Intersection, [&](EventTable& t) {
              t.integer(kPiece, i.piece_idx);
              t.number(kOffset, i.offset_mm);
              t.integer(kCode, i.intersection_code);
              t.boolean(kExiting, i.is_exiting != 0);
              t.integer(kSinceTransition, i.mm_since_last_transition_bar);
              if (i.mm_since_last_intersection_code)
                t.integer(kSinceIntersection, *i.mm_since_last_intersection_code);
            });
          },
          [&](const Delocalized&) { deliver(p, CarEvent::Delocalized, [](EventTable&) {}); },
          [&](const OffsetUpdate& o) {
            deliver(p, CarEvent::Offset, [&](EventTable& t) {
              t.number(kOffset, o.offset_mm);
              t.integer(kLaneChangeId, o.lane_change_id);
            });
          },
          [&](const BatteryResponse& b) {
            deliver(p, CarEvent::Battery, [&](EventTable& t) {
              const CarState& s = p.car->state();
              t.integer(kMillivolts, b.millivolts);
              t.boolean(kLow, s.battery_low);
              t.boolean(kFull, s.battery_full);
              t.boolean(kCharging, s.on_charger);
            });
          },
          [&](const VersionResponse& v) {
            deliver(p, CarEvent::Version, [&](EventTable& t) { t.integer(kVersion, v.version); });
          },
          [&](const PingResponse&) {
            deliver(p, CarEvent::Ping, [&](EventTable& t) {
              if (auto rtt = p.car->lastPingRtt()) t.number(kRtt, *rtt);
            });
          },
          [&](const CarStatus& s) {
            deliver(p, CarEvent::Status, [&](EventTable& t) {
              t.boolean(kOnTrack, s.on_track);
              t.boolean(kOnCharger, s.on_charger);
              t.boolean(kLowBattery, s.low_battery.value_or(false));
              t.boolean(kFullyCharged, s.fully_charged.value_or(false));
            });
          },
          [&](const Collision& c) {
            deliver(p, CarEvent::Collision, [&](EventTable& t) {
              t.integer(kSide, c.side);
              t.string(kWhere, c.front_back ? "back" : "front");
            });
          },
          [&](const SpeedUpdate& sp) {
            deliver(p, CarEvent::Speed, [&](EventTable& t) {
              t.integer(kDesired, sp.desired_mm_s);
              // firmware 0x266e's short form says the desired speed only: the others are nil
              if (sp.accel_mm_s2) t.integer(kAccel, *sp.accel_mm_s2);
              if (sp.actual_mm_s) t.integer(kActual, *sp.actual_mm_s);
            });
          },
          [&](const LaneChangeUpdate& lc) {
            deliver(p, CarEvent::LaneChange, [&](EventTable& t) {
              t.number(kCurrent, lc.current_offset_mm);
              t.number(kTarget, lc.target_offset_mm);
              t.integer(kHSpeed, lc.h_speed_mm_s);
              t.integer(kVSpeed, lc.v_speed_mm_s);
              t.integer(kLaneChangeId, lc.lane_change_id);
            });
          },
          [&](const AutoRecoveryEntered&) {
            deliver(p, CarEvent::Recovery, [](EventTable& t) { t.boolean(kSucceeded, false); });
          },
          [&](const AutoRecoverySucceeded&) {
            deliver(p, CarEvent::Recovery, [](EventTable& t) { t.boolean(kSucceeded, true); });
          },
          [](const auto&) {},  // commands, position updates (dispatch), reports with no event
      },
      m);
}

void CarBinding::deliverMessage(Proxy& p, const Message& m) {
  const auto message = static_cast<std::size_t>(CarEvent::Message);
  lua::emit({host_, p.slots, names_, p.selfRef, p.label}, message, LUA_NOREF, [&](lua_State* L) {
    nlohmann::json j = toJson(m);
    for (auto& [k, v] : j.items()) {
      if (v.is_boolean())
        lua_pushboolean(L, v.get<bool>());
      else if (v.is_number_integer())
        lua_pushinteger(L, v.get<lua_Integer>());
      else if (v.is_number())
        lua_pushnumber(L, v.get<double>());
      else
        lua_pushstring(L, v.is_string() ? v.get<std::string>().c_str() : v.dump().c_str());
      lua_setfield(L, -2, k.c_str());
    }
    lua::setNumber(L, "time", host_.loop().seconds());
  });
}

}  // namespace pitwall
