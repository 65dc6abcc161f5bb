#include "engine/drive/seats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"

namespace pitwall::drive {

namespace {
constexpr const char* kLog = "seats";
constexpr int kMaxLanes = 3;

std::string numberText(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

const char* holderName(Holder kind) {
  switch (kind) {
    case Holder::Phone:
      return "phone";
    case Holder::Gamepad:
      return "gamepad";
    case Holder::Keyboard:
      return "keyboard";
    case Holder::Script:
      return "script";
  }
  return "?";
}

Seats::Seats(Loop& loop, Fleet& fleet, int count, SeatsOptions options)
    : loop_(loop), fleet_(fleet), options_(options) {
  for (int i = 1; i <= count; ++i) seats_.push_back(Seat{.number = i});
}

Seats::~Seats() {
  if (silenceTimer_) loop_.cancel(*silenceTimer_);
  // Seats that go while held (a script's own, sim.openSeats, with its version on a reload) stop
  // the cars driven from them, as a holder that lets go would.
  for (auto& s : seats_)
    if (s.held() && s.live) lose(s, "its seats are gone");
}

Seat* Seats::find(const std::string& holder) {
  for (auto& s : seats_)
    if (s.holder == holder) return &s;
  return nullptr;
}

const Seat* Seats::seat(int number) const {
  if (number < 1 || number > static_cast<int>(seats_.size())) return nullptr;
  return &seats_[static_cast<std::size_t>(number - 1)];
}

const Seat* Seats::heldBy(const std::string& holder) const {
  for (const auto& s : seats_)
    if (s.holder == holder) return &s;
  return nullptr;
}

Result<int, std::string> Seats::claim(const std::string& holder, Holder kind, int number,
                                      const std::string& player) {
  if (seats_.empty())
    return Unexpected(std::string(
        "driving is off in this run: start it with --humans N to open cars 1..N to human "
        "drivers"));
  if (holder.empty()) return Unexpected(std::string("a holder needs a name"));
  const int n = static_cast<int>(seats_.size());
  if (number < 0 || number > n)
    return Unexpected("there is no seat " + std::to_string(number) + ": this run has seats 1.." +
                      std::to_string(n) + " (0 takes the first free one)");
  Seat* mine = find(holder);
  if (mine && (number == 0 || number == mine->number)) return mine->number;
  Seat* target = nullptr;
  if (number == 0) {
    for (auto& s : seats_)
      if (!s.held()) {
        target = &s;
        break;
      }
    if (!target)
      return Unexpected("every seat is taken (" + std::to_string(n) +
                        "): wait for a player to leave, or start the run with more --humans");
  } else {
    target = &seats_[static_cast<std::size_t>(number - 1)];
    if (target->held())
      return Unexpected(
          "seat " + std::to_string(number) + " is held by another " + holderName(target->kind) +
          (target->player.empty() ? "" : " (" + target->player + ")") + "; pick a free seat");
  }
  std::string before;
  if (mine) {  // (its old seat is let go once the new one is taken: no one can slip in between)
    before = holder + "#moving";
    mine->holder = before;
  }
  target->holder = holder;
  target->kind = kind;
  target->player = printable(player, 24);
  target->throttle = 0;
  target->lanes = 0;
  target->lastInput = loop_.seconds();
  target->live = true;
  log::info(kLog, std::string("seat ") + std::to_string(target->number) + " taken by a " +
                      holderName(kind) +
                      (target->player.empty() ? "" : " (" + target->player + ")"));
  armSilence();
  changed.emit(*target);
  if (mine) release(before, "took seat " + std::to_string(target->number));
  return target->number;
}

void Seats::release(const std::string& holder, const std::string& why) {
  Seat* s = find(holder);
  if (!s) return;
  lose(*s, why);
  s->holder.clear();
  s->player.clear();
  s->live = false;
  armSilence();
  changed.emit(*s);
}

Result<int, std::string> Seats::input(const std::string& holder, double throttle, int laneStep) {
  Seat* s = find(holder);
  if (!s) return Unexpected(std::string("no seat is held here: take one first"));
  if (!std::isfinite(throttle) || throttle < 0 || throttle > 1)
    return Unexpected("throttle " + numberText(throttle) +
                      " is out of range: give 0 (stop) to 1 (full)");
  if (laneStep < -1 || laneStep > 1)
    return Unexpected("lane step " + std::to_string(laneStep) +
                      " is out of range: -1 left, 0, +1 right");
  const bool wasLive = s->live;
  const bool news = throttle != s->throttle || laneStep != 0;
  s->throttle = throttle;
  s->lanes = std::clamp(s->lanes + laneStep, -kMaxLanes, kMaxLanes);
  s->lastInput = loop_.seconds();
  s->live = true;
  if (!wasLive) {
    log::info(kLog, "seat " + std::to_string(s->number) + ": input again");
    armSilence();
    changed.emit(*s);
  }
  if (news) asked.emit(*s);
  return s->number;
}

void Seats::driving(int number) {
  if (number < 1 || number > static_cast<int>(seats_.size())) return;
  Seat& s = seats_[static_cast<std::size_t>(number - 1)];
  s.drivenAt = loop_.seconds();
  const AnkiCar* car = fleet_.find(number);
  s.drivenSpeed = car ? car->state().target_speed_mm_s : 0;
}

int Seats::takeLanes(int number) {
  if (number < 1 || number > static_cast<int>(seats_.size())) return 0;
  return std::exchange(seats_[static_cast<std::size_t>(number - 1)].lanes, 0);
}

void Seats::lose(Seat& s, const std::string& why) {
  s.throttle = 0;
  s.lanes = 0;
  s.live = false;
  AnkiCar* car = fleet_.find(s.number);
  if (!car || !car->state().connected || car->halted()) {  // (the end of the run stopped it)
    log::debug(kLog, "seat " + std::to_string(s.number) + ": " + why);
    return;
  }
  const bool driven = loop_.seconds() - s.drivenAt <= kDrivenFor;
  const bool stillAsSeatAsked =
      s.drivenSpeed > 0 && car->state().target_speed_mm_s == s.drivenSpeed;
  if (!driven && !stillAsSeatAsked) {  // someone else drives the car now
    log::info(kLog, "seat " + std::to_string(s.number) + ": " + why +
                        " (no driver drives its car from it: the car is left to its driver)");
    return;
  }
  log::info(kLog, "seat " + std::to_string(s.number) + ": " + why + "; its car slows to a stop");
  if (auto sent = car->setSpeed(0, options_.stopDecel); !sent)
    log::warn(kLog, "seat " + std::to_string(s.number) + ": " + sent.error());
}

// One timer for every seat: due when the first live phone or script would fall silent; none
// while no such seat is live (a virtual run is not kept going by it).
void Seats::armSilence() {
  if (silenceTimer_) loop_.cancel(*silenceTimer_);
  silenceTimer_.reset();
  double due = INFINITY;
  for (const auto& s : seats_)
    if (s.live && (s.kind == Holder::Phone || s.kind == Holder::Script))
      due = std::min(due, s.lastInput + options_.silence);
  if (!std::isfinite(due)) return;
  const double wait = std::max(0.0, due - loop_.seconds());
  silenceTimer_ = loop_.after(fromSeconds(wait), [this] {
    silenceTimer_.reset();
    checkSilence();
  });
}

void Seats::checkSilence() {
  const double now = loop_.seconds();
  for (auto& s : seats_) {
    if (!s.live || !(s.kind == Holder::Phone || s.kind == Holder::Script)) continue;
    if (now - s.lastInput >= options_.silence - 1e-9) {
      lose(s, std::string("no input from its ") + holderName(s.kind) + " for " +
                  std::to_string(static_cast<int>(std::lround(options_.silence * 1000))) + " ms");
      changed.emit(s);
    }
  }
  armSilence();
}

}  // namespace pitwall::drive
