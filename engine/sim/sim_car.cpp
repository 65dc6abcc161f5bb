#include "engine/sim/sim_car.hpp"

#include <algorithm>
#include <cmath>

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/overload.hpp"
#include "engine/protocol/anki/codec.hpp"

namespace pitwall::sim {

namespace {

// Rules of the simulated car (docs/simulator.md has the reasoning behind each number).
constexpr double kMaxSpeed = 1500;          // mm/s: the fastest firmware (anki-overdrive.md)
constexpr double kMaxAccel = 25000;         // mm/s²: taken when a set-speed asks for 0
constexpr double kDefaultLaneSpeed = 100;   // mm/s: taken when a change-lane asks for 0
constexpr double kDefaultLaneAccel = 1000;  // mm/s²
constexpr double kStopDecel = 5000;         // mm/s²: a dropped connection stops the car
constexpr double kCoastDecel = 6000;        // mm/s²: a delocalized car coasts ≈190 mm from 1500
constexpr double kMaxLateralAccel = 9000;   // mm/s²: v²/r above this throws the car off a curve
// A car thrown by less than kSlideLimit times that slides outward by kSlideMm and, still on the
// road, loses the code for kFindMm of driving at kSlideSpeedFactor of its speed: then it reads the
// track again. Thrown harder, or slid off the road, it flies off (docs/simulator.md).
constexpr double kSlideLimit = 1.15;
constexpr double kSlideMm = 30;
constexpr double kFindMm = 200;
constexpr double kSlideSpeedFactor = 0.6;
constexpr double kOffRoadMm = 100;   // |offset| beyond this is off the road
constexpr double kHalfTrackMm = 20;  // wheel distance from the car's centre line
constexpr double kDrainMvPerMm = 500.0 / (20 * 60 * kMaxSpeed);  // 500 mV per 20 min flat out
constexpr double kLowBatteryMv = 3600;
constexpr double kFullBatteryMv = 4200;
constexpr std::uint8_t kBitsRead = 0x07;  // parsing flags low nibble: 7-bit codes (§4.5.1)
constexpr std::uint8_t kReverseDriving = 0x20;
constexpr std::uint8_t kReverseParsing = 0x40;  // the piece's codes read backwards

std::uint16_t clampU16(double v) {
  return static_cast<std::uint16_t>(std::clamp(std::lround(v), 0L, 65535L));
}
std::uint8_t clampCm(double mm) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(mm / 10), 0L, 255L));
}

}  // namespace

Car::Car(Environment& env, CarSpec spec, std::uint32_t identifier)
    : env_(env), spec_(std::move(spec)), identifier_(identifier) {
  piece_ = spec_.piece_index % env_.pieces.size();
  offset_ = spec_.offset_mm;
  double len = here().piece.length(offset_);
  u_ = std::clamp(spec_.distance_mm / len, 0.0, std::nextafter(1.0, 0.0));
  battery_mv_ = spec_.battery_mv;
  low_battery_ = battery_mv_ < kLowBatteryMv;
}

Car::~Car() {
  // The radio goes with the car: a connected controller learns that the car is gone.
  if (sink_) drop(true);
  if (outbox_timer_) env_.loop.cancel(outbox_timer_);
}

std::vector<std::uint8_t> Car::manufacturerData() const {
  // [BE EF][reserved][model][identifier, big-endian] (anki-overdrive.md "Advertisement")
  std::uint32_t id = identifier_;
  return {0xBE,
          0xEF,
          0x00,
          spec_.model_id,
          static_cast<std::uint8_t>(id >> 24),
          static_cast<std::uint8_t>(id >> 16),
          static_cast<std::uint8_t>(id >> 8),
          static_cast<std::uint8_t>(id)};
}

std::vector<std::uint8_t> Car::localName() const {
  // [state bits][version LE][5 reserved][user name, NUL-terminated], at most 20 bytes.
  std::vector<std::uint8_t> out(8, 0);
  if (battery_mv_ >= kFullBatteryMv) out[0] |= 0x10;
  if (low_battery_) out[0] |= 0x20;
  out[1] = static_cast<std::uint8_t>(spec_.version & 0xff);
  out[2] = static_cast<std::uint8_t>(spec_.version >> 8);
  for (char c : spec_.name) {
    if (out.size() >= 19) break;
    out.push_back(static_cast<std::uint8_t>(c));
  }
  out.push_back(0);
  return out;
}

// ---- the radio ----

void Car::connect(FrameSink toController, std::function<void()> onDropped) {
  if (sink_) drop(true);  // one controller at a time, as on a real car
  sink_ = std::move(toController);
  on_dropped_ = std::move(onDropped);
  sdk_ = false;
  sendStatus();
}

void Car::disconnect() {
  drop(false);
}

void Car::drop(bool notify) {
  if (!sink_) return;
  stop();
  sdk_ = false;
  sink_ = nullptr;
  outbox_.clear();
  if (outbox_timer_) env_.loop.cancel(outbox_timer_);
  outbox_timer_ = 0;
  auto dropped = std::move(on_dropped_);
  on_dropped_ = nullptr;
  if (notify && dropped) dropped();
}

void Car::stop() {
  target_ = 0;
  accel_ = kStopDecel;
}

void Car::receive(std::span<const std::uint8_t> frame) {
  if (!sink_) return;  // frames only arrive over a connection
  // As real firmware reads it, the short command forms too (anki-overdrive.md **Decision**).
  auto decoded = anki::decodeCommand(frame);
  if (!decoded) return refuse(frame, decoded.error().message());  // a real car ignores it
  const std::string_view what = anki::name(*decoded);
  // Driving commands need SDK mode (anki-overdrive.md "GATT"); answers are always given.
  const bool sdk = sdk_;
  auto driving = [&] {
    if (!sdk)
      refuse(frame, std::string(what) + " needs SDK mode, which is off (sdk-mode on: 03 90 01 01)");
    return sdk;
  };
  auto finite = [&](float offset_mm) {
    if (!std::isfinite(offset_mm))
      refuse(frame, std::string(what) + " offset " + std::to_string(offset_mm) + " is no distance");
    return std::isfinite(offset_mm);
  };
  std::visit(
      Overload{
          [&](const anki::PingRequest&) { emit(anki::PingResponse{}); },
          [&](const anki::VersionRequest&) { emit(anki::VersionResponse{spec_.version}); },
          [&](const anki::BatteryRequest&) { emit(anki::BatteryResponse{clampU16(battery_mv_)}); },
          [&](const anki::SdkMode& m) {
            sdk_ = m.on;
            if (sdk_) sendStatus();
          },
          [&](const anki::Disconnect&) { drop(true); },
          [&](const anki::SetSpeed& m) {
            if (!driving()) return;
            ++speed_commands_;
            if (m.speed_mm_s <= 0) ++stop_commands_;
            target_ = std::clamp<double>(m.speed_mm_s, 0, kMaxSpeed);
            accel_ = m.accel_mm_s2 > 0 ? m.accel_mm_s2 : kMaxAccel;
            anki::SpeedUpdate ack;
            ack.desired_mm_s = static_cast<std::int16_t>(target_);
            if (!olderFirmware()) {  // the older firmware's says the desired speed only
              ack.accel_mm_s2 = m.accel_mm_s2;
              ack.actual_mm_s = static_cast<std::int16_t>(std::lround(speed_));
            }
            emit(ack);
            if (target_ > 0) env_.wake();
          },
          [&](const anki::ChangeLane& m) {
            if (!driving() || !finite(m.offset_mm) || spec_.ghost) return;
            ++lane_recv_id_;
            lane_speed_asked_ = m.h_speed_mm_s;
            lane_speed_ = m.h_speed_mm_s > 0 ? m.h_speed_mm_s : kDefaultLaneSpeed;
            lane_accel_ = m.h_accel_mm_s2 > 0 ? m.h_accel_mm_s2 : kDefaultLaneAccel;
            // The target is relative to what the car believes (set-offset re-bases that belief).
            lane_target_ = (m.offset_mm - bias_) * dir_;
            lane_active_ = true;
            lane_vel_ = 0;
            env_.wake();
          },
          [&](const anki::CancelLaneChange&) {
            if (!driving() || spec_.ghost) return;
            lane_active_ = false;
            lane_vel_ = 0;
          },
          [&](const anki::SetOffset& m) {
            if (!driving() || !finite(m.offset_mm) || spec_.ghost) return;
            bias_ = m.offset_mm - offset_ * dir_;
          },
          [&](const anki::Turn& m) {
            if (!driving() || m.type == anki::TurnType::None || spec_.ghost) return;
            // Left/right turns and turns at the next intersection need an intersection piece.
            if (m.trigger != anki::TurnTrigger::Immediate ||
                (m.type != anki::TurnType::UTurn && m.type != anki::TurnType::UTurnJump))
              return refuse(frame,
                            "this turn needs an intersection piece, and no simulated "
                            "track has one (U-turns at once are taken)");
            dir_ = -dir_;
            bias_ = -bias_;  // what was believed right of the car is now left of it
            lane_active_ = false;
            lane_vel_ = 0;
          },
          // Lights and config change nothing the simulator models: taken, nothing to do.
          [&](const anki::SetLights&) {},
          [&](const anki::LightsPattern&) {},
          [&](const anki::SetConfig&) {},
          [&](const anki::Unknown& u) {
            refuse(frame, "message " + hexByte(u.id) + " is not one a car takes");
          },
          [&](const auto&) {  // the vehicle→controller ids
            refuse(frame, std::string(what) + " is a message cars send, not one they take");
          },
      },
      *decoded);
}

// What a real car ignores without a word is told here, so that a client's mistake shows.
void Car::refuse(std::span<const std::uint8_t> frame, const std::string& why) const {
  log::warn(spec_.name.empty() ? "sim car" : "sim car " + spec_.name,
            "ignored " + toHex(frame) + ": " + why);
}

// ---- physics ----

// A ghost drives its recorded lap again (CarSpec::ghost): its clock runs while a set-speed above
// 0 holds, and each tick it moves to where the lap had it at that time, along its recorded lane.
// From the actual position, so nothing drifts over many laps.
void Car::planGhost(double dt) {
  const GhostLap& g = *spec_.ghost;
  planned_lane_ = planned_centre_ = 0;
  if (target_ <= 0 || !on_track_ || g.time <= 0) {
    speed_ = 0;
    return;
  }
  ghost_clock_ += dt;
  const double laps = std::floor(ghost_clock_ / g.time);
  const double want = laps * env_.lap_mm + g.distanceAt(ghost_clock_ - laps * g.time);
  const double have = (laps_ - ghost_laps0_) * env_.lap_mm + lapPosition();
  const double advance = std::clamp(want - have, 0.0, GhostLap::kMaxSpeed * dt);
  offset_ = g.offsetAt(lapPosition(), spec_.offset_mm);
  // the lane's length for that much of the centre line, piece by piece
  double left = advance, lane = 0, u = u_;
  std::size_t piece = piece_;
  while (left > 0) {
    const PieceInfo& p = env_.pieces[piece];
    const double rest = (1 - u) * p.centre_mm;
    const double step = std::min(left, rest);
    lane += step * p.piece.length(offset_) / p.centre_mm;
    left -= step;
    u = 0;
    piece = (piece + 1) % env_.pieces.size();
  }
  planned_centre_ = advance;
  planned_lane_ = lane;
  speed_ = dt > 0 ? lane / dt : 0;
}

void Car::plan(double dt) {
  if (spec_.ghost) return planGhost(dt);
  if (delocalized_ && !sliding()) {
    speed_ = std::max(0.0, speed_ - kCoastDecel * dt);
  } else if (speed_ < target_) {
    speed_ = std::min(target_, speed_ + accel_ * dt);
  } else if (speed_ > target_) {
    speed_ = std::max(target_, speed_ - accel_ * dt);
    // Real cars report a collision as they come to a halt from speed (docs/simulator.md).
    if (speed_ == 0 && on_track_ && sensor::reportsHalt(env_.sensor, peak_))
      emit(anki::Collision{1, 0});
  }
  peak_ = speed_ > 0 ? std::max(peak_, speed_) : 0;

  // Lateral move toward the target lane: accelerate to the asked lateral speed, and slow down
  // in time to arrive without overshoot. A car steers only while it rolls.
  if (lane_active_ && !delocalized_ && speed_ > 0) {
    double remaining = lane_target_ - offset_;
    double dist = std::abs(remaining);
    double v =
        std::min({lane_speed_, lane_vel_ + lane_accel_ * dt, std::sqrt(2 * lane_accel_ * dist)});
    double step = v * dt;
    if (step >= dist) {
      offset_ = lane_target_;
      lane_active_ = false;
      lane_vel_ = 0;
      lane_exec_id_ = lane_recv_id_;
      if (on_track_) emit(anki::OffsetUpdate{static_cast<float>(believedOffset()), lane_exec_id_});
    } else {
      offset_ += remaining > 0 ? step : -step;
      lane_vel_ = v;
    }
  }

  planned_lane_ = speed_ * dt;
  planned_centre_ = planned_lane_ * here().centre_mm / here().piece.length(offset_);
}

void Car::holdAt(double centre_mm, double speed) {
  planned_lane_ = centre_mm * here().piece.length(offset_) / here().centre_mm;
  planned_centre_ = centre_mm;
  speed_ = speed;
}

void Car::collided(bool rear) {
  ++collisions_;
  emit(anki::Collision{0, static_cast<std::uint8_t>(rear ? 1 : 0)});
}

void Car::commit() {
  if (planned_lane_ <= 0) return;
  move(planned_lane_);
  if (sliding()) {
    find_left_mm_ -= planned_lane_;
    if (find_left_mm_ <= 0) delocalized_ = false;  // it reads the track again
  }
  if (!delocalized_) {
    battery_mv_ -= kDrainMvPerMm * planned_lane_;
    if (!low_battery_ && battery_mv_ < kLowBatteryMv) {
      low_battery_ = true;
      sendStatus();
    }
  }
  if (!spec_.ghost) checkDelocalization();
}

void Car::move(double lane_mm) {
  const bool reporting = on_track_ && !delocalized_;
  for (;;) {
    const PieceInfo& p = here();
    double len = p.piece.length(offset_);
    double left = dir_ > 0 ? (1 - u_) * len : u_ * len;
    double step = std::min(lane_mm, left);
    bool crosses = step >= left;
    double nu = crosses ? (dir_ > 0 ? 1.0 : 0.0) : u_ + dir_ * step / len;
    if (reporting) {
      // At most one code per tick in practice; loop in driving order to be safe.
      const PieceInfo::Row& row = p.rows[static_cast<std::size_t>(rowAt(p))];
      const int codes = static_cast<int>(row.code_at.size());
      for (int k = 0; k < codes; ++k) {
        int idx = dir_ > 0 ? k : codes - 1 - k;
        double f = row.code_at[static_cast<std::size_t>(idx)];
        if ((dir_ > 0 ? (f > u_ && f <= nu) : (f < u_ && f >= nu)) && reads(p))
          sendPosition(row.location[static_cast<std::size_t>(idx)], row.reversed != (dir_ < 0));
      }
    }
    // Wheels run on lanes of their own: in a curve the outer wheel travels further.
    wheel_left_mm_ += step * p.piece.length(offset_ - kHalfTrackMm * dir_) / len;
    wheel_right_mm_ += step * p.piece.length(offset_ + kHalfTrackMm * dir_) / len;
    u_ = nu;
    lane_mm -= step;
    if (!crosses) return;
    crossBoundary();
    if (lane_mm <= 0) return;
  }
}

void Car::crossBoundary() {
  const bool reporting = on_track_ && !delocalized_;
  if (reporting) {
    sendTransition();
    double phantom = sensor::phantomCollisionChance(env_.sensor, speed_);
    if (phantom > 0 && uniform() < phantom) emit(anki::Collision{0, 1});
  }
  std::size_t n = env_.pieces.size();
  piece_ = dir_ > 0 ? (piece_ + 1) % n : (piece_ + n - 1) % n;
  u_ = dir_ > 0 ? 0.0 : 1.0;
  wheel_left_mm_ = wheel_right_mm_ = 0;
  // The finish line lies between 34 and 33 (anki-overdrive.md "Track"); on a track without them,
  // at the beginning of its first piece (Track::finishIndex).
  if (reporting && dir_ > 0 && piece_ == env_.track.finishIndex()) ++laps_;
}

void Car::checkDelocalization() {
  if (!on_track_ || delocalized_) return;
  bool off = std::abs(offset_) > kOffRoadMm;
  bool thrown = false;
  const Piece& p = here().piece;
  double excess = 0;
  if (p.type == anki::PieceType::Curve && speed_ > 0) {
    double r = p.radius() + p.turn * offset_;
    excess = r <= 0 ? 1e9 : speed_ * speed_ / r / kMaxLateralAccel;
    thrown = excess > 1;
  }
  if (thrown && !off && excess < kSlideLimit) {
    // outward: a left curve (turn +1) has its outside at larger offsets (r = radius + offset)
    double slid = offset_ + p.turn * kSlideMm;
    if (std::abs(slid) <= kOffRoadMm) return slide(slid);
  }
  if (off || thrown) delocalize();
}

void Car::slide(double offset) {
  ++slides_;
  offset_ = offset;
  speed_ *= kSlideSpeedFactor;
  find_left_mm_ = kFindMm;
  delocalized_ = true;  // on the road, the code lost: nothing reported until it is found again
  lane_active_ = false;
  lane_vel_ = 0;
  emit(anki::Delocalized{});
}

void Car::delocalize() {
  delocalized_ = true;
  on_track_ = false;
  lane_active_ = false;
  lane_vel_ = 0;
  emit(anki::Delocalized{});
  sendStatus();
}

bool Car::active() const {
  if (spec_.ghost) return target_ > 0 && on_track_;
  return speed_ > 0 || (target_ > 0 && on_track_);  // (on the track and delocalized: sliding)
}

double Car::lapPosition() const {
  return here().lap_start_mm + u_ * here().centre_mm;
}

// ---- test hooks ----

void Car::reboot(Duration down) {
  drop(true);
  speed_ = target_ = 0;
  sdk_ = false;
  lane_active_ = false;
  lane_vel_ = 0;
  bias_ = 0;
  boot_until_ = env_.loop.now() + down;
}

bool Car::connectable() const {
  return env_.loop.now() >= boot_until_;
}

void Car::lift() {
  speed_ = 0;
  if (!on_track_) {
    delocalized_ = true;
    return;
  }
  delocalize();
}

void Car::place(std::size_t piece_index, double offset_mm) {
  piece_ = piece_index % env_.pieces.size();
  u_ = 0;
  dir_ = 1;
  offset_ = offset_mm;
  bias_ = 0;
  speed_ = target_ = 0;
  lane_active_ = false;
  lane_vel_ = 0;
  wheel_left_mm_ = wheel_right_mm_ = 0;
  delocalized_ = false;
  on_track_ = true;
  sendStatus();
}

Truth Car::truth() const {
  Truth t;
  t.piece_index = piece_;
  t.piece_id = here().piece.id;
  t.piece_distance_mm = u_ * here().piece.length(offset_);
  t.lap_distance_mm = lapPosition();
  t.offset_mm = offset_;
  t.speed_mm_s = speed_;
  t.target_speed_mm_s = target_;
  t.laps = laps_;
  t.on_track = on_track_;
  t.delocalized = delocalized_;
  t.sdk_mode = sdk_;
  t.connected = static_cast<bool>(sink_);
  t.battery_mv = clampU16(battery_mv_);
  t.collisions = collisions_;
  t.slides = slides_;
  t.speed_commands = speed_commands_;
  t.stop_commands = stop_commands_;
  t.ghost = static_cast<bool>(spec_.ghost);
  return t;
}

// ---- frames out ----

void Car::sendStatus() {
  emit(anki::CarStatus{on_track_, false, low_battery_, battery_mv_ >= kFullBatteryMv});
}

int Car::rowAt(const PieceInfo& p) const {
  // The code row under the car: rows are numbered in the piece's own frame, so a car driving
  // it backwards reads the same location ids (seed 000 §4.5.1), in the other order.
  const int rows = static_cast<int>(p.rows.size());
  return std::clamp(static_cast<int>(std::floor(offset_ / p.row_pitch_mm + rows / 2.0)), 0,
                    rows - 1);
}

bool Car::reads(const PieceInfo& p) {
  double radius = p.piece.radius() + p.piece.turn * offset_;
  double chance = sensor::readChance(env_.sensor, p.piece.type, speed_, radius);
  return chance >= 1 || uniform() < chance;
}

void Car::sendPosition(int location_id, bool read_backwards) {
  anki::PositionUpdate m;
  m.location_id = static_cast<std::uint8_t>(location_id);
  const PieceInfo& p = here();
  m.piece_id = p.piece.id;
  m.offset_mm = static_cast<float>(believedOffset());
  double reported = speed_;
  if (env_.sensor != SensorModel::Ideal) {
    double u1 = uniform();
    reported = sensor::reportedSpeed(env_.sensor, speed_, u1, uniform());
  }
  m.speed_mm_s = clampU16(reported);
  m.parsing_flags = static_cast<std::uint8_t>(kBitsRead | (dir_ < 0 ? kReverseDriving : 0) |
                                              (read_backwards ? kReverseParsing : 0));
  m.last_recv_lane_change_id = lane_recv_id_;
  m.last_exec_lane_change_id = lane_exec_id_;
  m.last_desired_lane_change_speed_mm_s = lane_speed_asked_;
  m.last_desired_speed_mm_s = clampU16(target_);
  emit(m);
}

void Car::sendTransition() {
  anki::TransitionUpdate m;
  m.piece_idx = 0;  // always 0 on real cars (anki-overdrive.md, firmware variants)
  m.prev_piece_idx = 0;
  m.offset_mm = static_cast<float>(believedOffset());
  // The older firmware's 19-byte layout: 0 forward, as IBM's captured frame (an assumption for
  // reversed: 1)
  if (olderFirmware()) m.driving_direction = static_cast<std::uint8_t>(dir_ < 0 ? 1 : 0);
  m.last_recv_lane_change_id = lane_recv_id_;
  m.last_exec_lane_change_id = lane_exec_id_;
  m.last_desired_lane_change_speed_mm_s = lane_speed_asked_;
  m.had_lane_change_activity = lane_recv_id_ != 0 ? 1 : 0;
  m.left_wheel_distance_cm = clampCm(wheel_left_mm_);
  m.right_wheel_distance_cm = clampCm(wheel_right_mm_);
  emit(m);
}

double Car::uniform() {
  // 53 random bits → [0, 1): fixed arithmetic, so every platform draws the same numbers.
  return static_cast<double>(env_.rng() >> 11) * 0x1.0p-53;
}

void Car::emit(const anki::Message& message) {
  if (!sink_) return;
  const Noise& noise = env_.noise;
  if (noise.drop > 0 && uniform() < noise.drop) return;
  TimePoint now = env_.loop.now();
  TimePoint due = now;
  if (noise.late > 0 && uniform() < noise.late)
    due += Duration(
        static_cast<Duration::rep>(uniform() * static_cast<double>(noise.late_by.count())));
  // BLE keeps order: a frame never overtakes one held back before it.
  if (!outbox_.empty()) due = std::max(due, outbox_.back().due);
  if (due == now && outbox_.empty()) {
    anki::Frame frame = anki::encode(message);
    sink_(frame.span());
    return;
  }
  outbox_.push_back({due, anki::encode(message)});
  if (!outbox_timer_)
    outbox_timer_ = env_.loop.at(outbox_.front().due, [this] {
      outbox_timer_ = 0;
      flushOutbox();
    });
}

void Car::flushOutbox() {
  TimePoint now = env_.loop.now();
  while (!outbox_.empty() && outbox_.front().due <= now) {
    anki::Frame frame = outbox_.front().frame;
    outbox_.pop_front();
    if (sink_) sink_(frame.span());
  }
  if (!outbox_.empty() && !outbox_timer_)
    outbox_timer_ = env_.loop.at(outbox_.front().due, [this] {
      outbox_timer_ = 0;
      flushOutbox();
    });
}

}  // namespace pitwall::sim
