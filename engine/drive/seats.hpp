#pragma once
// Human seats (docs/racing.md "Human drivers"): the cars a run opens to people (--humans N:
// cars 1..N), who holds each one, and what its holder asks for — a throttle 0..1 and lane steps.
// Phones (the view's /drive page), gamepads, the terminal's keyboard and scripts are holders;
// a human driver of the race library reads the seat and commands the car.
//
// The engine keeps a held car safe, whatever the script does:
// - a holder that lets go (a phone disconnects, a gamepad is unplugged) frees the seat, and
// - a phone or script that says nothing for `silence` s (1 s) loses its input;
// either way the throttle reads 0 and, while a driver drives the car from the seat (the human
// driver), the car is slowed to a stop here, at once — not left at speed until the driver
// notices. Gamepads and keyboards hold a throttle without sending (a trigger
// held still sends nothing), so silence is no loss for them: their loss is the device's.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/core/signal.hpp"
#include "engine/fleet/fleet.hpp"

namespace pitwall::drive {

enum class Holder { Phone, Gamepad, Keyboard, Script };
const char* holderName(Holder kind);  // "phone", "gamepad", "keyboard", "script"

struct SeatsOptions {
  double silence = 1.0;  // s without input after which a phone's or a script's seat is lost
  int stopDecel = 1500;  // mm/s²: how a car whose holder is gone or silent is slowed to a stop
};

struct Seat {
  int number = 0;      // 1, 2, …: the car number it drives (seat 2 drives car 2)
  std::string holder;  // who holds it (a phone's connection, a device path); empty: free
  Holder kind = Holder::Phone;
  std::string player;        // the name the holder gave ("Anna"; a gamepad's device name)
  double throttle = 0;       // 0..1 as last asked; 0 while not live
  int lanes = 0;             // lane steps asked and not taken yet: − left, + right (at most ±3)
  double lastInput = 0;      // engine seconds of the last input
  double drivenAt = -1e300;  // engine seconds a driver last said it drives from this seat
  int drivenSpeed = 0;       // the car's commanded speed then (mm/s)
  bool live = false;         // held, and its input is fresh
  bool held() const { return !holder.empty(); }
};

class Seats {
 public:
  // Seats for cars 1..count. The cars are looked up when needed: a car may join later.
  Seats(Loop& loop, Fleet& fleet, int count, SeatsOptions options = {});
  ~Seats();
  Seats(const Seats&) = delete;
  Seats& operator=(const Seats&) = delete;

  // `holder` takes seat `number`, or the first free one when 0; it keeps any seat it held
  // already only when it asks for that one again (one seat a holder). The error says why: no
  // such seat (and how many there are), held by someone else, none free, driving is off.
  Result<int, std::string> claim(const std::string& holder, Holder kind, int number = 0,
                                 const std::string& player = {});
  // The holder lets go of its seat (if any): freed, and its car slowed to a stop. `why` is logged.
  void release(const std::string& holder, const std::string& why);
  // What the holder asks for now: throttle 0..1 (other values, NaN, ±inf are refused) and lane
  // steps (−1 left, +1 right, 0 none). Also the sign of life that keeps a phone's seat live.
  Result<int, std::string> input(const std::string& holder, double throttle, int laneStep);

  // The seats, in number order.
  const std::vector<Seat>& all() const { return seats_; }
  const Seat* seat(int number) const;
  const Seat* heldBy(const std::string& holder) const;
  // The lane steps asked since the last take (− left, + right); they are forgotten.
  int takeLanes(int number);
  // A driver drives seat `number`'s car from the seat now, and has just commanded it (the human
  // driver says so after each update and while the lights are on). A lost holder stops the car
  // while one does — said within kDrivenFor s — and also later, as long as the car still goes
  // at the speed it last had from the seat's driver (nothing else commanded it since: a driver
  // that stopped being called, a reload's pause, a long period). A car that the race director
  // drives (a scan lap, to the grid) or an AI driver drives is not the seat's to stop.
  void driving(int number);
  static constexpr double kDrivenFor = 1.0;
  std::size_t count() const { return seats_.size(); }

  // A seat changed hands or liveness: the view redraws its list; gamepads look for a free seat.
  Signal<const Seat&> changed;
  // A holder asked for another throttle or a lane step (the view shows the throttle).
  Signal<const Seat&> asked;

 private:
  Seat* find(const std::string& holder);
  void lose(Seat& seat, const std::string& why);  // throttle 0, car slowed to a stop
  void armSilence();
  void checkSilence();

  Loop& loop_;
  Fleet& fleet_;
  SeatsOptions options_;
  std::vector<Seat> seats_;
  std::optional<Loop::TimerId> silenceTimer_;
};

}  // namespace pitwall::drive
