#pragma once
// A simulated Anki car: the vehicle side of the protocol plus its physics on a track. Private to
// engine/sim; everything else sees it as a SimCar. The rules are written up in docs/simulator.md.
#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/protocol/anki/firmware.hpp"
#include "engine/protocol/anki/messages.hpp"
#include "engine/sim/sensor.hpp"
#include "engine/sim/world.hpp"

namespace pitwall::sim {

// Per-piece facts the cars look up every tick, computed once per world.
struct PieceInfo {
  Piece piece;
  double centre_mm = 0;     // length along the centre line
  double lap_start_mm = 0;  // centre-line distance from the finish line to this piece's start
  // The location codes of each code row (engine/sim/code_layout.hpp): where the car reports
  // them, as fractions of the piece (forward), and the row's first location id.
  struct Row {
    std::vector<double> code_at;
    std::vector<int> location;  // the location id of each code, in the same order
    bool reversed = false;      // its ids run against the layout (a right curve): read backwards
  };
  std::vector<Row> rows;  // left to right in the piece's forward direction
  double row_pitch_mm = 12;
};

// What a car shares with its world. Owned by the world; outlives its cars.
struct Environment {
  Loop& loop;
  const Track& track;
  std::vector<PieceInfo> pieces;
  double lap_mm = 0;  // centre-line lap length
  Noise noise;
  SensorModel sensor = SensorModel::Real;
  std::mt19937_64 rng;
  std::function<void()> wake;  // a car has something to do: make sure the world ticks
};

class Car final : public SimCar {
 public:
  Car(Environment& env, CarSpec spec, std::uint32_t identifier);
  ~Car() override;

  // SimCar
  const CarSpec& spec() const override { return spec_; }
  std::uint32_t identifier() const override { return identifier_; }
  std::vector<std::uint8_t> manufacturerData() const override;
  std::vector<std::uint8_t> localName() const override;
  void connect(FrameSink toController, std::function<void()> onDropped) override;
  void disconnect() override;
  void receive(std::span<const std::uint8_t> frame) override;
  Truth truth() const override;
  double believedOffset() const override { return offset_ * dir_ + bias_; }
  void lift() override;
  void reboot(Duration down) override;
  bool connectable() const override;
  std::weak_ptr<const void> lifetime() const override { return life_; }
  void place(std::size_t piece_index, double offset_mm) override;

  // The world's tick, in three phases over all cars in a fixed order:
  // plan → (world resolves collisions with holdAt) → commit.
  void plan(double dt);
  void commit();
  // Collision resolution: the car may advance at most `centre_mm` this tick and takes `speed`.
  void holdAt(double centre_mm, double speed);
  void collided(bool rear);  // counts the contact and sends a collision frame

  bool active() const;                                      // needs ticks (moving, or about to)
  bool solid() const { return on_track_ && !spec_.ghost; }  // other cars bump into it
  int direction() const { return dir_; }
  double trackOffset() const { return offset_; }
  double speed() const { return speed_; }
  double lapPosition() const;  // centre line, from the finish line, [0, lap)
  double plannedAdvance() const { return planned_centre_; }

 private:
  const PieceInfo& here() const { return env_.pieces[piece_]; }
  int rowAt(const PieceInfo& p) const;  // the code row under the car
  void planGhost(double dt);
  void move(double lane_mm);
  void crossBoundary();
  void checkDelocalization();
  void delocalize();
  void slide(double offset);  // thrown a little: slid outward to `offset`, the code lost a while
  bool sliding() const { return delocalized_ && on_track_; }
  void stop();
  void drop(bool notify);

  void refuse(std::span<const std::uint8_t> frame, const std::string& why) const;
  void emit(const anki::Message& message);
  void flushOutbox();
  double uniform();  // [0, 1) from the world's generator, by our own arithmetic
  void sendStatus();
  bool reads(const PieceInfo& p);  // whether passing a code yields a position (the sensor model)
  void sendPosition(int location_id, bool read_backwards);
  void sendTransition();
  // Firmware before 0x2b6e: the older layouts (docs/simulator.md "Firmware families").
  bool olderFirmware() const { return anki::olderLayouts(spec_.version); }

  Environment& env_;
  CarSpec spec_;
  std::uint32_t identifier_;

  // Where: piece index, fraction of that piece travelled in the track's forward direction,
  // driving direction (+1 along the layout, −1 after a U-turn), true offset in the track frame.
  std::size_t piece_ = 0;
  double u_ = 0;
  int dir_ = 1;
  double offset_ = 0;
  double bias_ = 0;  // believed − true offset, in the driving frame (set-offset re-bases it)

  double speed_ = 0, target_ = 0, accel_ = 0;
  double peak_ = 0;  // the fastest since the car last stood (a halt from speed reports, Sensor)
  double planned_lane_ = 0, planned_centre_ = 0;

  bool lane_active_ = false;
  double lane_target_ = 0;  // true offset, track frame
  double lane_vel_ = 0, lane_speed_ = 0, lane_accel_ = 0;
  std::uint8_t lane_recv_id_ = 0, lane_exec_id_ = 0;
  std::uint16_t lane_speed_asked_ = 0;

  bool on_track_ = true, delocalized_ = false, sdk_ = false, low_battery_ = false;
  double battery_mv_ = 0;
  int laps_ = 0, collisions_ = 0, slides_ = 0;
  double ghost_clock_ = 0;   // a ghost: seconds of its lap driven (CarSpec::ghost)
  int ghost_laps0_ = 0;      // laps_ when it set off
  double find_left_mm_ = 0;  // sliding: mm to drive until it reads the track again
  TimePoint boot_until_{};   // rebooting: not connectable before this
  std::shared_ptr<const int> life_ = std::make_shared<const int>(0);
  int speed_commands_ = 0, stop_commands_ = 0;  // Truth::speed_commands, stop_commands
  double wheel_left_mm_ = 0, wheel_right_mm_ = 0;

  FrameSink sink_;
  std::function<void()> on_dropped_;
  struct Delayed {
    TimePoint due;
    anki::Frame frame;
  };
  std::deque<Delayed> outbox_;  // frames held back by the `late` noise, in order
  Loop::TimerId outbox_timer_ = 0;
};

}  // namespace pitwall::sim
