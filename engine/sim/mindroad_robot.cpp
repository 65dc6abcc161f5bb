// The simulated MindRoad robot car: the behaviour rules of ../shared/protocols/mindroad.md.
#include "engine/sim/mindroad_robot.hpp"

#include "engine/core/numbers.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <type_traits>

namespace pitwall::sim {

using namespace mindroad;

namespace {
std::string seconds(double s) {
  return formatNumber(s, 3) + " s";
}
}  // namespace

void MindroadRobot::changed(const std::string& event, const std::string& detail) {
  if (onChange) onChange(event, detail);
}

void MindroadRobot::stop(const std::string& event, const std::string& why) {
  state_.steerX = 0;
  state_.steerY = 0;
  state_.lastStop = why;
  changed(event, why);
}

void MindroadRobot::advance(double now) {
  const double dt = now - lastAdvance_;
  if (dt > 0 && state_.moving()) {
    // y > 0 steers right: clockwise, so the heading (counter-clockwise) goes down.
    const double speed = options_.maxSpeed * state_.steerX / 127.0;
    const double turn = -options_.maxTurnRate * state_.steerY / 127.0;
    const double dh = turn * dt;
    const double mid = (state_.heading + dh / 2) * std::numbers::pi / 180;
    state_.x += speed * dt * std::cos(mid);
    state_.y += speed * dt * std::sin(mid);
    state_.heading = std::fmod(state_.heading + dh, 360.0);
    if (state_.heading < 0) state_.heading += 360;
  }
  lastAdvance_ = now;
  // Watchdog (seed 002 §3, mindroad.md "Behaviour"): no instruction for a while → stop and wait
  // for a new contact.
  if (state_.contact && now - lastInstruction_ > options_.watchdog) {
    state_.contact = false;
    stop("watchdog", "no instruction for " + seconds(now - lastInstruction_) + " (watchdog " +
                         seconds(options_.watchdog) + "): stopped; waiting for a new contact");
  }
}

std::vector<std::uint8_t> MindroadRobot::receive(const Result<Instruction, DecodeError>& in,
                                                 double now) {
  advance(now);
  ++state_.instructions;
  if (!in.ok()) {
    // A malformed instruction stops the robot but keeps contact (mindroad.md "Behaviour").
    ++state_.malformed;
    if (state_.contact) lastInstruction_ = now;
    stop("malformed", "malformed instruction: " + in.error().message() + "; stopped");
    return {};
  }
  const Instruction& i = *in;
  if (std::holds_alternative<Contact>(i)) {
    if (contactsIgnored_ < options_.ignoreContacts) {
      ++contactsIgnored_;
      ++state_.ignored;
      changed("ignored", "contact " + std::to_string(contactsIgnored_) + " ignored (test setting)");
      return {};
    }
    ++state_.contacts;
    lastInstruction_ = now;
    const bool was = state_.contact;
    state_.contact = true;
    if (!was) changed("contact", "contact: answered K");
    return {kContactAnswer};
  }
  if (std::holds_alternative<Stop>(i)) {
    if (state_.contact) lastInstruction_ = now;
    stop("stop", "stop instruction");
    return {};
  }
  if (std::holds_alternative<Shutdown>(i)) {
    state_.shutdown = true;
    stop("shutdown", "shutdown instruction: turning off");
    return {};
  }
  if (!state_.contact) {
    // After a watchdog stop (or before the first contact) the robot waits for contact.
    ++state_.ignored;
    changed("ignored", std::string(name(i)) + " ignored: no contact (send contact first)");
    return {};
  }
  lastInstruction_ = now;
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, Steering>) {
          if (m.x == state_.steerX && m.y == state_.steerY) return;
          state_.steerX = m.x;
          state_.steerY = m.y;
          changed("steer", "steering x " + std::to_string(m.x) + ", y " + std::to_string(m.y));
        } else if constexpr (std::is_same_v<T, MousePosition>) {
          state_.clickX = m.x;
          state_.clickY = m.y;
          changed("click", "click at " + std::to_string(m.x) + ", " + std::to_string(m.y));
        } else if constexpr (std::is_same_v<T, Buttons>) {
          state_.buttons = m.raw;
          if (auto b = m.asId()) {
            if (*b == Button::Manual || *b == Button::Automatic)
              state_.mode = std::string(buttonName(*b));
            else
              state_.sensitivity += *b == Button::SensitivityUp ? 1 : -1;
          }
          changed("buttons", "buttons " + std::to_string(m.raw));
        } else if constexpr (std::is_same_v<T, PictureMode>) {
          state_.picture = m.mode;
          changed("picture-mode", "picture mode " + std::string(pictureName(m.mode)));
        }
        // Ping: nothing but the watchdog reset above.
      },
      i);
  return {};
}

}  // namespace pitwall::sim
