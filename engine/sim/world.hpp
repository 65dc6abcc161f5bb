#pragma once
// The simulated world: a track and the cars on it, stepped on the engine loop. Simulated cars
// implement the *vehicle* side of the Anki protocol: they take controller frames and send
// vehicle frames, encoded and decoded by the same codec the real cars' controller uses.
// Rules (docs/simulator.md): physics tick, location codes, delocalization, collisions, battery.
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/protocol/anki/firmware.hpp"
#include "engine/sim/sensor.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::sim {

// A recorded lap that a ghost car drives again (sim.addGhost, docs/simulator.md "Ghosts"): where
// the car was along the track's centre line from the finish line, and its lane, at each time of
// the lap. Made from a record's lap (engine/laps); the simulator only reads it.
struct GhostLap {
  struct Point {
    double t = 0;         // s since the lap began at the line
    double distance = 0;  // mm along the centre line from the line
  };
  std::vector<Point> points;  // t and distance never decreasing, from (0, 0) to (time, length)
  struct Lane {
    double distance = 0, offset = 0;  // mm from the line; mm right of the centre
  };
  std::vector<Lane> lanes;  // where the car said its lane; none: the spec's offset all lap
  double time = 0;          // the lap's time, s
  double length = 0;        // the lap's centre-line length, mm (the track's)
  // Faster than this on average is no lap a car drove (a record's times are any numbers): a
  // ghost never goes faster, nor takes such a lap (sim.addGhost refuses it).
  static constexpr double kMaxSpeed = 5000;  // mm/s
  double distanceAt(double t) const;         // linear between the points
  double offsetAt(double distance, double otherwise) const;
};

struct CarSpec {
  std::string name;                                // user name in the advertisement
  std::uint8_t model_id = 8;                       // Groundshock
  std::uint32_t identifier = 0;                    // 0: the world assigns one
  std::size_t piece_index = 0;                     // index into track.pieces() where the car starts
  double distance_mm = 0;                          // how far into that piece (along its lane)
  double offset_mm = 0;                            // lateral offset from road centre, mm (+ right)
  std::uint16_t version = anki::kFirmwareDefault;  // docs/simulator.md "Firmware families"
  std::uint16_t battery_mv = 4100;
  // Set: a ghost. It starts at the finish line and, while a set-speed above 0 holds, drives this
  // lap again and again exactly as recorded; it touches no car, slides off no curve, and takes
  // no lane change or turn.
  std::shared_ptr<const GhostLap> ghost = nullptr;
};

struct Noise {
  double drop = 0;  // probability that a vehicle→controller frame is lost
  double late = 0;  // probability that one is delayed
  Duration late_by{std::chrono::milliseconds(150)};  // upper bound of that delay
};

// Ground truth of a simulated car, for tests and the `pitwall.sim` Lua module.
struct Truth {
  std::size_t piece_index = 0;
  std::uint8_t piece_id = 0;
  double piece_distance_mm = 0;  // along the car's lane within the piece
  double lap_distance_mm = 0;    // along the centre line from the finish line, 0..lap length
  double offset_mm = 0;
  double speed_mm_s = 0;
  double target_speed_mm_s = 0;
  int laps = 0;  // finish lines crossed (34 → 33) while on track
  bool on_track = true;
  bool delocalized = false;
  bool sdk_mode = false;
  bool connected = false;
  std::uint16_t battery_mv = 0;
  int collisions = 0;
  int slides = 0;          // times thrown off a curve and slid on, still on the road
  int speed_commands = 0;  // set-speed frames received in SDK mode
  int stop_commands = 0;   // those of them that asked for 0 mm/s
  bool ghost = false;      // a ghost car (CarSpec::ghost)
};

class SimCar {
 public:
  using FrameSink = std::function<void(std::span<const std::uint8_t>)>;
  virtual ~SimCar() = default;

  virtual const CarSpec& spec() const = 0;
  virtual std::uint32_t identifier() const = 0;
  // Manufacturer data (8 raw bytes) and local name bytes as the car would advertise them.
  virtual std::vector<std::uint8_t> manufacturerData() const = 0;
  virtual std::vector<std::uint8_t> localName() const = 0;

  // The radio: a controller connects, frames flow, either side may drop the connection.
  virtual void connect(FrameSink toController, std::function<void()> onDropped) = 0;
  virtual void disconnect() = 0;  // controller side went away: the car stops
  virtual void receive(std::span<const std::uint8_t> frame) = 0;  // controller → vehicle

  virtual Truth truth() const = 0;
  // The offset the car believes it has (what its next report would say): its true offset
  // until a set offset re-bases the belief (docs/simulator.md "Believed offset").
  virtual double believedOffset() const = 0;
  // Test hooks: lift the car off the track (it delocalizes and stops reporting) and put it back.
  virtual void lift() = 0;
  virtual void place(std::size_t piece_index, double offset_mm) = 0;
  // Test hook: the car resets, as on a tired cell under hard acceleration: its connection drops,
  // it stands where it is with everything forgotten (SDK mode off, speed 0, no lane change, its
  // believed offset its true one), and it can be connected again `down` later.
  virtual void reboot(Duration down) = 0;
  virtual bool connectable() const = 0;  // not booting
  // Expires with the car (its world destroyed): a link that looks again later checks it first.
  virtual std::weak_ptr<const void> lifetime() const = 0;
};

class World {
 public:
  static constexpr Duration kTick = std::chrono::milliseconds(5);

  World(Loop& loop, Track track, std::uint64_t seed);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const Track& track() const;
  Loop& loop();
  SimCar& addCar(CarSpec spec);
  std::vector<SimCar*> cars();
  void setNoise(Noise noise);
  const Noise& noise() const;
  // What the cars' sensors report (engine/sim/sensor.hpp): `Real` (the default), fitted to a
  // physical car's frames, or `Ideal`: every code (docs/simulator.md "Sensor model").
  void setSensor(SensorModel model);
  SensorModel sensor() const;
  // Ticks made up for because the loop ran them late (real time only; docs/simulator.md
  // "Real time"): the cars moved on by the wall clock meanwhile.
  std::uint64_t lateTicks() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace pitwall::sim
