#pragma once
// The controller-side model of one Anki Overdrive car: its state as last reported, validated
// commands that become frames on its link, and typed events from the frames it sends. The same
// code serves simulated and real cars: only the Link differs.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/core/signal.hpp"
#include "engine/core/warning_limit.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/transport/link.hpp"

namespace pitwall {

struct CarIdentity {
  int number = 0;    // 1-based, in the order cars joined the run
  std::string name;  // user name from the advertisement, or "car<n>"
  std::uint8_t model_id = 0;
  std::uint32_t identifier = 0;
  bool ghost = false;  // the simulator's ghost of a recorded lap (sim.addGhost): it races no one
};

// Frames of one message that came longer than its layout (anki-overdrive.md **Decision**): read by
// the layout all the same; the bytes past it are kept so that a user can see what a firmware
// appends.
struct ExtraBytes {
  std::uint64_t frames = 0;        // frames of that message with bytes past its layout
  std::vector<std::uint8_t> last;  // those bytes of the latest one
};

struct CarState {
  bool connected = false;
  bool on_track = false;
  bool on_charger = false;
  bool delocalized = false;
  bool reverse = false;       // parsing flag 0x20: driving backwards
  int speed_mm_s = 0;         // as last reported
  int target_speed_mm_s = 0;  // as last commanded
  int piece = -1;             // road piece id, −1 before the first position update
  int prev_piece = -1;        // piece of the position update before the last one
  int location = -1;
  // From road centre, as the car believes it: from its reports, and before the first one where
  // the link knows it stands (a simulated car; Link::knownOffset), else 0.
  double offset_mm = 0;
  std::optional<double> lane_change_target_mm;  // set while a lane change is under way
  int battery_mv = 0;                           // 0 until known
  bool battery_low = false;
  bool battery_full = false;
  int version = 0;  // firmware version, 0 until known
  double last_position_time = -1;
  std::uint64_t frames_in = 0, frames_out = 0, malformed = 0;
  std::map<std::string, ExtraBytes, std::less<>> extra_bytes;  // by message name
  // The link's story (car.link, docs/lua-api.md): connections made, drops, the last drop's reason
  int connects = 0;
  int drops = 0;
  std::string last_drop;
  // Notifications missed, as far as the model can tell: times a car told to drive and reporting
  // a speed, connected all along, sent nothing for longer than it takes to cross two pieces at
  // that speed (kSilenceMm; a real car sends a transition at every piece boundary) and at least
  // kSilence s — until it speaks again or is told to stop; and the longest such silence (s).
  int silences = 0;
  double longest_silence = 0;
  double last_frame_time = -1;  // loop seconds of the car's last frame
  // The round trip of the last request the car answered (ping, version, battery: asked at each
  // connection), in s; −1 before any.
  double round_trip = -1;
};

// A driving car silent this long (s), and over this distance at its speed (mm: two of the
// longest pieces), has lost notifications (CarState::silences).
inline constexpr double kSilence = 1.0;
inline constexpr double kSilenceMm = 1120;

// Why a lane change to a car that stands is refused, and what to do (docs/lua-api.md).
inline constexpr const char* kLaneChangeNeedsMotion =
    "a lane change needs a moving car (real cars steer only while they roll); setSpeed first "
    "(300 mm/s or more changes lanes reliably), then changeLane";

// Command defaults (docs/lua-api.md)
inline constexpr int kDefaultAccel = 1000;      // mm/s²
inline constexpr int kStopAccel = 12500;        // mm/s², brisk but not a crash stop
inline constexpr int kDefaultLaneSpeed = 300;   // mm/s
inline constexpr int kDefaultLaneAccel = 3000;  // mm/s²

class AnkiCar {
 public:
  using Error = std::string;
  using Sent = Result<bool, Error>;  // true, or a sentence saying why nothing was sent
  enum class Direction { Rx, Tx };

  AnkiCar(Loop& loop, Link& link, CarIdentity identity);
  AnkiCar(const AnkiCar&) = delete;
  AnkiCar& operator=(const AnkiCar&) = delete;

  const CarIdentity& identity() const { return identity_; }
  const CarState& state() const { return state_; }
  Link& link() { return link_; }
  const Link& link() const { return link_; }
  std::string label() const;  // "car 2 (groundshock)"

  // Commands: validated; an invalid or undeliverable one is refused with a sentence.
  Sent setSpeed(int speed_mm_s, int accel_mm_s2 = kDefaultAccel, bool respect_limit = false);
  Sent stop();
  Sent changeLane(double offset_mm, int h_speed_mm_s = kDefaultLaneSpeed,
                  int h_accel_mm_s2 = kDefaultLaneAccel);
  Sent setOffset(double offset_mm);
  Sent cancelLaneChange();
  Sent turn(anki::TurnType type, anki::TurnTrigger trigger = anki::TurnTrigger::Immediate);
  Sent lights(int mask);
  Sent lightsPattern(const anki::LightsPattern& pattern);
  Sent ping();
  Sent requestBattery();
  Sent requestVersion();
  Sent sdkMode(bool on, std::uint8_t flags = 0x01);
  Sent disconnect();
  // Any controller→vehicle message, validated (the CLI and bridges use this).
  Sent send(const anki::Message& message);
  // The end of the run (docs/safety.md): a stop, when connected, and from then on no command
  // but a disconnect is sent, whoever asks (a script, the REPL, an MQTT intent). Final.
  Sent halt();
  bool halted() const { return halted_; }
  // A pause (Ctrl-Z, docs/safety.md): a stop, when connected, and until resume() every command
  // but a disconnect is refused with "`why`: … was not sent". Unlike halt() it ends: after
  // resume() the car takes commands again (it stays stopped until one comes).
  Sent pause(const std::string& why);
  void resume() { paused_.clear(); }
  bool paused() const { return !paused_.empty(); }

  // Events, on the loop. Every message, after it updated state(): to the run's Lua world, whose
  // one slot this is (the hot path of every frame, docs/performance.md: a plain call), then to
  // every other listener — a driver world's car objects (docs/drivers.md) — each holding its
  // subscription.
  std::function<void(const anki::Message&)> onMessage;
  Signal<const anki::Message&> messages;
  // Every connection change (the fleet, which subscribes first, then the Lua objects).
  Signal<bool /*connected*/, const std::string& /*reason*/> connectionChanged;
  // Every frame that does not decode, with its bytes.
  Signal<const anki::DecodeError&, std::span<const std::uint8_t>> malformed;
  // Round-trip time of the last ping, delivered with the ping response (seconds).
  std::optional<double> lastPingRtt() const { return lastPingRtt_; }
  // Every frame in and out, for recording.
  std::function<void(Direction, std::span<const std::uint8_t>, const anki::Message&)> onFrame;

  // Forgets what the car's frames said (a replay moving back to its start): the state as it
  // was when the car connected.
  void rewind();

  // Entry point of frames from the link (public for tests and benchmarks).
  void receive(std::span<const std::uint8_t> frame);

 private:
  void apply(const anki::Message& message);
  void keepExtra(const anki::Message& message, std::span<const std::uint8_t> extra);
  void linkStateChanged(bool up, const std::string& reason);
  void laneChangeReached();
  void answered(std::optional<double>& sentAt);  // a request answered: its round trip
  void noteSilence();
  // Why the car counts as standing (a lane change is refused), or nullopt when it moves.
  std::optional<std::string> standing() const;

  Loop& loop_;
  Link& link_;
  CarIdentity identity_;
  CarState state_;
  bool halted_ = false;
  std::string paused_;           // why the car takes no command now (pause()), or empty
  double speedReportedAt_ = -1;  // loop seconds of the last frame that said the car's speed
  std::optional<double> pingSentAt_;
  std::optional<double> lastPingRtt_;
  std::optional<double> versionSentAt_, batterySentAt_;
  double movingSince_ = -1;     // loop seconds since the car was told to drive (−1: stands)
  double connectedSince_ = -1;  // loop seconds of the last connection
  double stoppedAt_ = -1;       // loop seconds the car was last told to stop
  int silenceSpeed_ = 0;        // its speed at its last frame if it was told to drive, else 0
  // A car or link that sends only malformed frames: the first warned, then a count each 5 s.
  WarningLimit malformedWarnings_{loop_, "malformed frames ignored"};
};

}  // namespace pitwall
