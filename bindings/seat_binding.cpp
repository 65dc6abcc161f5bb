// pitwall.seats: the seats of human drivers (docs/racing.md "Human drivers"), as a script sees
// them. The seats are the run's (--humans N) or, in the simulator, a script's own
// (sim.openSeats(n): a scenario's stand-in for the command line).
//   pitwall.seats()          → {seat, …} in number order (empty: no seats)
//   pitwall.seat(n)          → seat n or nil
//   seat.number, seat.car (the car object, nil until it is there), seat.held, seat.live,
//   seat.holder ("phone" | "gamepad" | "keyboard" | "script" | nil), seat.player, seat.throttle
//   seat:lanes()             → the lane steps asked since the last call (− left, + right)
//   seat:feed(throttle [, lane])  the script holds the seat and asks for this (scripted input)
//   seat:release()           the script lets go of the seat (its car slows to a stop)
//   seat:driving()           a driver drives the car from the seat now (at every update): only
//                            then does a lost holder stop the car (engine/drive/seats.hpp)
#include <string>

#include "bindings/car_binding.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/script_host.hpp"
#include "engine/drive/seats.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

constexpr const char* kSeatMetatable = "pitwall.seat";

drive::Seats* seatsOf(lua_State* L) {
  return ScriptHost::from(L).seats();
}

std::string scriptHolder(int number) {
  return "script#" + std::to_string(number);
}

const lua::TypeSpec& seatType();

int seatNumber(lua_State* L, int idx) {
  return lua::check<int>(L, idx, seatType());
}

const drive::Seat& checkSeat(lua_State* L, int idx) {
  const int number = seatNumber(L, idx);
  drive::Seats* seats = seatsOf(L);
  const drive::Seat* seat = seats ? seats->seat(number) : nullptr;
  if (!seat) throw LuaError("seat " + std::to_string(number) + " is gone");
  return *seat;
}

void pushSeat(lua_State* L, int number) {
  lua::newBox<int>(L, seatType(), number);
}

// ---- state fields: one entry each ----
void pushOptionalString(lua_State* L, bool present, const std::string& v) {
  present ? (void)lua_pushlstring(L, v.data(), v.size()) : lua_pushnil(L);
}

const lua::Field kSeatFields[] = {
    {"number", [](lua_State* L, int self) { lua_pushinteger(L, checkSeat(L, self).number); }},
    {"car",
     [](lua_State* L, int self) {
       ScriptHost& host = ScriptHost::from(L);
       AnkiCar* car = host.fleet().find(checkSeat(L, self).number);
       car ? host.cars().push(L, *car) : lua_pushnil(L);
     }},
    {"held", [](lua_State* L, int self) { lua_pushboolean(L, checkSeat(L, self).held()); }},
    {"live", [](lua_State* L, int self) { lua_pushboolean(L, checkSeat(L, self).live); }},
    {"holder",
     [](lua_State* L, int self) {
       const drive::Seat& s = checkSeat(L, self);
       pushOptionalString(L, s.held(), s.held() ? drive::holderName(s.kind) : "");
     }},
    {"player",
     [](lua_State* L, int self) {
       const drive::Seat& s = checkSeat(L, self);
       pushOptionalString(L, s.held() && !s.player.empty(), s.player);
     }},
    {"throttle",
     [](lua_State* L, int self) {
       const drive::Seat& s = checkSeat(L, self);
       lua_pushnumber(L, s.live ? s.throttle : 0.0);
     }},
};

int seatLanes(lua_State* L) {
  const drive::Seat& s = checkSeat(L, 1);
  lua_pushinteger(L, seatsOf(L)->takeLanes(s.number));
  return 1;
}

int seatFeed(lua_State* L) {
  const drive::Seat& s = checkSeat(L, 1);
  const double throttle = lua::checkNumber(L, 2, "the throttle");
  const long long lane = lua::optInteger(L, 3, "the lane step", 0);
  drive::Seats& seats = *seatsOf(L);
  const std::string holder = scriptHolder(s.number);
  if (seats.heldBy(holder) == nullptr) {
    auto claimed = seats.claim(holder, drive::Holder::Script, s.number, "script");
    if (!claimed) throw LuaError("seat:feed: " + claimed.error());
  }
  if (lane < -1 || lane > 1)
    throw LuaError("seat:feed: the lane step must be -1 (left), 0 or 1 (right), got " +
                   std::to_string(lane));
  auto fed = seats.input(holder, throttle, static_cast<int>(lane));
  if (!fed) throw LuaError("seat:feed: " + fed.error());
  return 0;
}

int seatDriving(lua_State* L) {
  const drive::Seat& s = checkSeat(L, 1);
  seatsOf(L)->driving(s.number);
  return 0;
}

int seatRelease(lua_State* L) {
  const drive::Seat& s = checkSeat(L, 1);
  seatsOf(L)->release(scriptHolder(s.number), "the script let go");
  return 0;
}

std::string seatLabel(lua_State* L, int self) {
  const int number = seatNumber(L, self);
  drive::Seats* seats = seatsOf(L);
  const drive::Seat* s = seats ? seats->seat(number) : nullptr;
  std::string text = "seat " + std::to_string(number);
  if (s && s->held())
    text += std::string(" (") + drive::holderName(s->kind) +
            (s->player.empty() ? "" : " " + s->player) + (s->live ? "" : ", no input") + ")";
  else
    text += " (free)";
  return text;
}

const lua::TypeSpec& seatType() {
  static const luaL_Reg methods[] = {{"lanes", lua::guarded<seatLanes>},
                                     {"feed", lua::guarded<seatFeed>},
                                     {"release", lua::guarded<seatRelease>},
                                     {"driving", lua::guarded<seatDriving>},
                                     {nullptr, nullptr}};
  static const lua::TypeSpec type{
      .metatable = kSeatMetatable,
      .name = "seat",
      .methods = methods,
      .fields = kSeatFields,
      .label = seatLabel,
  };
  return type;
}

int seatsList(lua_State* L) {
  drive::Seats* seats = seatsOf(L);
  const int n = seats ? static_cast<int>(seats->count()) : 0;
  lua_createtable(L, n, 0);
  for (int i = 1; i <= n; ++i) {
    pushSeat(L, i);
    lua_rawseti(L, -2, i);
  }
  return 1;
}

int seatOne(lua_State* L) {
  const long long n = lua::checkInteger(L, 1, "the seat number");
  drive::Seats* seats = seatsOf(L);
  if (!seats || !seats->seat(static_cast<int>(n))) {
    lua_pushnil(L);
    return 1;
  }
  pushSeat(L, static_cast<int>(n));
  return 1;
}

// sim.openSeats(n): the simulator's stand-in for --humans N (scenario tests feed the seats).
int openSeats(lua_State* L) {
  const long long n = lua::checkInteger(L, 1, "the number of seats");
  if (n < 1 || n > 64)
    throw LuaError("sim.openSeats: give 1 to 64 seats, got " + std::to_string(n));
  ScriptHost& host = ScriptHost::from(L);
  if (host.seats())
    throw LuaError("sim.openSeats: this run has its seats already (" +
                   std::to_string(host.seats()->count()) + ")");
  host.openSeats(static_cast<int>(n));
  return seatsList(L);
}

}  // namespace

void openSeatModule(ScriptHost& host) {
  lua_State* L = host.state();
  lua::registerType(L, seatType());

  lua_getglobal(L, "pitwall");
  lua_pushcfunction(L, lua::guarded<seatsList>);
  lua_setfield(L, -2, "seats");
  lua_pushcfunction(L, lua::guarded<seatOne>);
  lua_setfield(L, -2, "seat");
  if (host.sim() && !host.options().seats) {
    if (lua_getfield(L, -1, "sim") == LUA_TTABLE) {
      lua_pushcfunction(L, lua::guarded<openSeats>);
      lua_setfield(L, -2, "openSeats");
    }
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
}

}  // namespace pitwall
