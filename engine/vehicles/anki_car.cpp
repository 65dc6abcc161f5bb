#include "engine/vehicles/anki_car.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/limits.hpp"

namespace pitwall {

using namespace anki;

AnkiCar::AnkiCar(Loop& loop, Link& link, CarIdentity identity)
    : loop_(loop), link_(link), identity_(std::move(identity)) {
  link_.onFrame([this](std::span<const std::uint8_t> f) { receive(f); });
  link_.onState([this](bool up, const std::string& why) { linkStateChanged(up, why); });
  state_.connected = link_.connected();
  state_.offset_mm = link_.knownOffset().value_or(0);
  // What stop() sends, for the stop that does not need the loop (engine/core/emergency_stops.hpp)
  link_.setEmergencyStop(encode(SetSpeed{0, static_cast<int16_t>(kStopAccel), false}).span());
}

std::string AnkiCar::label() const {
  std::string l = "car " + std::to_string(identity_.number);
  if (!identity_.name.empty()) l += " (" + identity_.name + ")";
  return l;
}

AnkiCar::Sent AnkiCar::send(const Message& message) {
  if (auto problem = limits::validate(message)) return Unexpected{*problem};
  if (halted_ && !std::holds_alternative<Disconnect>(message))
    return Unexpected{label() + " was stopped for the end of the run and takes no more commands; " +
                      std::string(name(message)) + " was not sent"};
  if (!paused_.empty() && !std::holds_alternative<Disconnect>(message))
    return Unexpected{label() + ": " + paused_ + "; " + std::string(name(message)) +
                      " was not sent"};
  if (!link_.connected())
    return Unexpected{label() + " is not connected; " + std::string(name(message)) +
                      " was not sent"};
  Frame frame = encode(message);
  if (!link_.send(frame.span())) {
    std::string why = link_.refusal();
    return Unexpected{label() + ": " + std::string(name(message)) +
                      " was not sent: " + (why.empty() ? "the link refused it" : why)};
  }
  ++state_.frames_out;
  if (onFrame) onFrame(Direction::Tx, frame.span(), message);
  return true;
}

AnkiCar::Sent AnkiCar::setSpeed(int speed, int accel, bool respect_limit) {
  if (auto e = checkRange("speed", speed, limits::kSpeedMin, limits::kSpeedMax, "mm/s"))
    return Unexpected{*e};
  if (auto e = checkRange("acceleration", accel, limits::kAccelMin, limits::kAccelMax, "mm/s²"))
    return Unexpected{*e};
  auto sent =
      send(SetSpeed{static_cast<int16_t>(speed), static_cast<int16_t>(accel), respect_limit});
  if (sent) {
    if (speed == 0) {
      if (movingSince_ >= 0) stoppedAt_ = loop_.seconds();
      movingSince_ = -1;
    } else if (state_.target_speed_mm_s == 0) {
      movingSince_ = loop_.seconds();
    }
    state_.target_speed_mm_s = speed;
  }
  return sent;
}

AnkiCar::Sent AnkiCar::stop() {
  return setSpeed(0, kStopAccel);
}

AnkiCar::Sent AnkiCar::pause(const std::string& why) {
  if (halted_) return true;  // stopped for good already
  paused_.clear();
  auto sent = link_.connected() ? stop() : Sent{true};
  paused_ = why;
  return sent;
}

AnkiCar::Sent AnkiCar::halt() {
  if (halted_) return true;
  paused_.clear();
  auto sent = link_.connected() ? stop() : Sent{true};
  halted_ = true;
  return sent;
}

AnkiCar::Sent AnkiCar::changeLane(double offset, int h_speed, int h_accel) {
  if (auto e = checkRange("lane-change speed", h_speed, limits::kLaneSpeedMin,
                          limits::kLaneSpeedMax, "mm/s"))
    return Unexpected{*e};
  if (auto e = checkRange("lane-change acceleration", h_accel, limits::kLaneAccelMin,
                          limits::kLaneAccelMax, "mm/s²"))
    return Unexpected{*e};
  const ChangeLane message{static_cast<uint16_t>(h_speed), static_cast<uint16_t>(h_accel),
                           static_cast<float>(offset), 0, 0};
  if (auto problem = limits::validate(message)) return Unexpected{*problem};  // the offset
  if (auto e = halted_ ? std::nullopt : standing())  // halted: send() says so
    return Unexpected{*e + "; " + kLaneChangeNeedsMotion};
  auto sent = send(message);
  if (sent) state_.lane_change_target_mm = offset;
  return sent;
}

// A car steers only while it rolls (anki-overdrive.md: lane changes need the car to be moving):
// a lane change sent to a car that stands would be dropped by a real car, or carried out at
// some later start, so it is refused here. The car moves when it was told to drive (even before
// it reports anything), or when it reported a speed above 0 within the last half second (it
// rolls, also while it brakes behind another car); a car that stops falls silent and its last
// report stays, so an older one counts as standing — the rule of drivers.moving.
std::optional<std::string> AnkiCar::standing() const {
  constexpr double kRecent = 0.5;  // seconds
  const double age = loop_.seconds() - speedReportedAt_;
  const bool rolling = state_.speed_mm_s > 0 && speedReportedAt_ >= 0 && age <= kRecent;
  if (!state_.connected || state_.target_speed_mm_s > 0 || rolling)
    return std::nullopt;  // not connected: send() says so
  if (state_.speed_mm_s == 0) return label() + " stands (speed 0 mm/s)";
  char text[160];
  std::snprintf(text, sizeof text,
                " stands (target speed 0 mm/s; its last report, %d mm/s, is %.1f s old)",
                static_cast<int>(state_.speed_mm_s), age);
  return label() + text;
}

AnkiCar::Sent AnkiCar::setOffset(double offset) {
  auto sent = send(SetOffset{static_cast<float>(offset)});
  if (sent) state_.offset_mm = offset;
  return sent;
}

AnkiCar::Sent AnkiCar::cancelLaneChange() {
  auto sent = send(CancelLaneChange{});
  if (sent) state_.lane_change_target_mm.reset();
  return sent;
}

AnkiCar::Sent AnkiCar::turn(TurnType type, TurnTrigger trigger) {
  return send(Turn{type, trigger});
}

AnkiCar::Sent AnkiCar::lights(int mask) {
  if (auto e = checkRange("lights mask", mask, 0, 255)) return Unexpected{*e};
  return send(SetLights{static_cast<uint8_t>(mask)});
}

AnkiCar::Sent AnkiCar::lightsPattern(const LightsPattern& pattern) {
  return send(pattern);
}

AnkiCar::Sent AnkiCar::ping() {
  auto sent = send(PingRequest{});
  if (sent) pingSentAt_ = loop_.seconds();
  return sent;
}

AnkiCar::Sent AnkiCar::requestBattery() {
  auto sent = send(BatteryRequest{});
  if (sent) batterySentAt_ = loop_.seconds();
  return sent;
}
AnkiCar::Sent AnkiCar::requestVersion() {
  auto sent = send(VersionRequest{});
  if (sent) versionSentAt_ = loop_.seconds();
  return sent;
}
AnkiCar::Sent AnkiCar::sdkMode(bool on, std::uint8_t flags) {
  return send(SdkMode{on, flags});
}

AnkiCar::Sent AnkiCar::disconnect() {
  if (!link_.connected()) return Unexpected{label() + " is not connected"};
  auto sent = send(Disconnect{});
  link_.disconnect();
  return sent;
}

void AnkiCar::rewind() {
  state_ = CarState{};
  state_.connected = link_.connected();
  state_.connects = state_.connected ? 1 : 0;  // (connected before what is replayed again)
  state_.offset_mm = link_.knownOffset().value_or(0);
  pingSentAt_.reset();
  lastPingRtt_.reset();
  versionSentAt_.reset();
  batterySentAt_.reset();
  movingSince_ = stoppedAt_ = -1;
  silenceSpeed_ = 0;
  connectedSince_ = state_.connected ? loop_.seconds() : -1;
}

void AnkiCar::receive(std::span<const std::uint8_t> frame) {
  auto decoded = decode(frame);
  if (!decoded) {
    ++state_.malformed;
    malformedWarnings_.warn(label(), "malformed frame ignored: " + decoded.error().message());
    malformed.emit(decoded.error(), frame);
    return;
  }
  ++state_.frames_in;
  noteSilence();
  if (auto extra = extraBytesOfReceived(frame); !extra.empty()) keepExtra(*decoded, extra);
  apply(*decoded);
  silenceSpeed_ = movingSince_ >= 0 ? state_.speed_mm_s : 0;
  if (onFrame) onFrame(Direction::Rx, frame, *decoded);
  if (onMessage) onMessage(*decoded);
  messages.emit(*decoded);
}

// A frame longer than its layout is no error (anki-overdrive.md **Decision**): counted per message,
// its extra bytes kept, and the first of each message told once.
void AnkiCar::keepExtra(const Message& message, std::span<const std::uint8_t> extra) {
  const std::string_view what = name(message);
  auto it = state_.extra_bytes.find(what);
  if (it == state_.extra_bytes.end()) {
    it = state_.extra_bytes.emplace(std::string(what), ExtraBytes{}).first;
    log::warn(label(), std::string(what) + " came " + std::to_string(extra.size()) +
                           (extra.size() == 1 ? " byte" : " bytes") + " longer than its layout (" +
                           toHex(extra) +
                           "): read by the layout, the extra bytes counted and kept");
  }
  ++it->second.frames;
  it->second.last.assign(extra.begin(), extra.end());
}

// The offset update (0x2d) that ends a lane change may be lost on the radio: a car that reports
// itself at the target has arrived all the same.
void AnkiCar::laneChangeReached() {
  constexpr double kArrivedMm = 2.0;
  if (state_.lane_change_target_mm &&
      std::fabs(state_.offset_mm - *state_.lane_change_target_mm) <= kArrivedMm)
    state_.lane_change_target_mm.reset();
}

void AnkiCar::apply(const Message& message) {
  // Only the messages that change what we know of the car; the rest pass through as events.
  if (auto* p = std::get_if<PositionUpdate>(&message)) {
    state_.prev_piece = state_.piece;
    state_.piece = p->piece_id;
    state_.location = p->location_id;
    state_.offset_mm = p->offset_mm;
    state_.speed_mm_s = p->speed_mm_s;
    state_.reverse = (p->parsing_flags & 0x20) != 0;
    state_.on_track = true;
    state_.delocalized = false;
    state_.last_position_time = loop_.seconds();
    speedReportedAt_ = state_.last_position_time;
    laneChangeReached();
  } else if (auto* t = std::get_if<TransitionUpdate>(&message)) {
    state_.offset_mm = t->offset_mm;
    laneChangeReached();
  } else if (auto* o = std::get_if<OffsetUpdate>(&message)) {
    state_.offset_mm = o->offset_mm;
    state_.lane_change_target_mm.reset();
  } else if (std::holds_alternative<Delocalized>(message)) {
    state_.delocalized = true;
    state_.speed_mm_s = 0;
    state_.lane_change_target_mm.reset();  // the car gave up whatever it was doing
  } else if (std::holds_alternative<AutoRecoverySucceeded>(message)) {
    state_.delocalized = false;
  } else if (auto* s = std::get_if<SpeedUpdate>(&message); s && s->actual_mm_s) {
    state_.speed_mm_s = *s->actual_mm_s;  // firmware 0x266e's short form does not say it
    speedReportedAt_ = loop_.seconds();
  } else if (auto* b = std::get_if<BatteryResponse>(&message)) {
    state_.battery_mv = b->millivolts;
    answered(batterySentAt_);
  } else if (auto* v = std::get_if<VersionResponse>(&message)) {
    state_.version = v->version;
    answered(versionSentAt_);
  } else if (auto* c = std::get_if<CarStatus>(&message)) {
    state_.on_track = c->on_track;
    state_.on_charger = c->on_charger;
    if (c->low_battery) state_.battery_low = *c->low_battery;
    if (c->fully_charged) state_.battery_full = *c->fully_charged;
  } else if (std::holds_alternative<PingResponse>(message)) {
    if (pingSentAt_) lastPingRtt_ = loop_.seconds() - *pingSentAt_;
    answered(pingSentAt_);
  }
}

void AnkiCar::answered(std::optional<double>& sentAt) {
  if (sentAt) state_.round_trip = loop_.seconds() - *sentAt;
  sentAt.reset();
}

// A frame from the car: was it silent since its last one — driving then, connected all along —
// for longer than its speed explains (until now, or until it was told to stop)?
void AnkiCar::noteSilence() {
  const double now = loop_.seconds(), last = state_.last_frame_time;
  state_.last_frame_time = now;
  if (last < 0 || silenceSpeed_ <= 0 || connectedSince_ > last) return;
  const double end = stoppedAt_ >= last ? stoppedAt_ : now;
  const double gap = end - last;
  if (gap < std::max(kSilence, kSilenceMm / silenceSpeed_)) return;
  ++state_.silences;
  state_.longest_silence = std::max(state_.longest_silence, gap);
}

void AnkiCar::linkStateChanged(bool up, const std::string& reason) {
  state_.connected = up;
  if (up) {
    ++state_.connects;
    connectedSince_ = loop_.seconds();
  } else {
    ++state_.drops;
    state_.last_drop = reason;
  }
  // Before its first position update the offset is where the link knows the car stands (a
  // simulated car placed since it joined), or what it was.
  if (up && state_.last_position_time < 0)
    state_.offset_mm = link_.knownOffset().value_or(state_.offset_mm);
  if (up) {
    // Without SDK mode the car ignores speed and lane commands (anki-overdrive.md "GATT").
    if (auto sent = sdkMode(true); !sent) log::warn(label(), sent.error());
    requestVersion();
    requestBattery();
  } else {
    // A car whose connection dropped stops (a real car, the simulator's): told nothing since, it
    // is told to stand, so a driver that drives it again after a reconnection sends its speed.
    state_.speed_mm_s = 0;
    state_.target_speed_mm_s = 0;
    movingSince_ = -1;
    silenceSpeed_ = 0;
    state_.lane_change_target_mm.reset();
    pingSentAt_.reset();
    versionSentAt_.reset();
    batterySentAt_.reset();
  }
  log::info(label(), up ? "connected" : "disconnected: " + reason);
  connectionChanged.emit(up, reason);
}

}  // namespace pitwall
