#pragma once
// One run, as `pitwall run` and `pitwall test` set it up: the loop, the cars (simulated in a
// world, or real ones over Bluetooth LE) and the Lua host, destroyed in the right order.
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "bindings/reloader.hpp"
#include "engine/classroom/classroom.hpp"
#include "engine/cli/commands.hpp"
#include "engine/core/emergency_stops.hpp"
#include "engine/core/lag_monitor.hpp"
#include "engine/core/log.hpp"
#include "engine/core/loop.hpp"
#include "engine/core/stop_signals.hpp"
#include "engine/drive/gamepads.hpp"
#include "engine/drive/keyboard.hpp"
#include "engine/drive/seats.hpp"
#include "engine/fleet/ble_central.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/mqtt/bridge.hpp"
#include "engine/mqtt/remote.hpp"
#include "engine/record/recorder.hpp"
#include "engine/sim/track.hpp"
#include "engine/transport/mqtt_client.hpp"
#include "engine/view/feed.hpp"
#include "engine/view/server.hpp"

namespace pitwall::cli {

class Session {
 public:
  // On the built-in simulator.
  Session(ClockKind clock, sim::Track track, std::uint64_t seed);
  // Real cars through BlueZ, on the real clock. Throws ble::BleError when there is no bus.
  explicit Session(ble::CentralOptions options);
  // A replay (pitwall replay): no simulator, no radio; the record's cars join the fleet.
  explicit Session(ClockKind clock);
  ~Session();

  // The session `pitwall COMMAND` asks for with `source` (the simulator in real time, or in
  // virtual time when `fast`; or BLE), catching SIGINT and SIGTERM: the first interrupts the Lua
  // code running, stops the cars and ends the run with status 130; a second leaves at once (the
  // stops are sent all the same). nullptr after printing "pitwall COMMAND: why" (exit status 2).
  static std::unique_ptr<Session> open(const CarSource& source, bool fast, const char* command);
  // The session of a replay, catching SIGINT and SIGTERM as open() does.
  static std::unique_ptr<Session> openReplay(ClockKind clock);
  // Puts the cars of the source on the run (the grid, or the real cars found, then with --mqtt the
  // remote cars). 0, or the exit status after printing why not: 1 (simulated cars did not
  // connect), 2 (no BLE cars, no broker, too few remote cars), 130.
  int connectCars(const char* command);
  // pitwall bridge: publishes this session's cars on the broker and executes intents. 0, or 2
  // after printing why not (a bad setting, or the broker refused this client).
  int startBridge(const MqttSettings& mqtt, const std::string& hostId, bool readOnly,
                  const char* command);
  MqttBridge* bridge() { return bridge_.get(); }
  MqttClient* mqtt() { return mqtt_.get(); }  // the broker's client (bridge, remote cars)
  // From here on SIGINT is someone else's (the REPL's); SIGTERM still ends the run.
  void releaseSigint();
  bool interrupted() const { return interrupted_; }

  Loop& loop() { return loop_; }
  Fleet& fleet() { return fleet_; }
  SimSession& sim() { return sim_; }
  ScriptHost& host() { return scripts_->host(); }  // the Lua world now (hot reload replaces it)
  Reloader& scripts() { return *scripts_; }

  // --record: checked now (throws std::runtime_error naming the file), opened by openRecord()
  // once the start can no longer be refused; the frames before it are kept until then.
  void record(const std::string& path);
  void recordRace(const nlohmann::json& race);
  void openRecord();  // throws std::runtime_error naming the file
  // Puts `count` cars on the starting grid and runs the loop until all are connected.
  bool addGridCars(int count);
  // --ghost (docs/racing.md "Racing a ghost"): the track a ghost drives — the simulator's, or
  // the layout --ble --track gives; nullptr with real cars and no layout.
  const sim::Track* ghostTrack() const;
  // The ghost joins after the grid (or the real cars), as a simulated car of its own world
  // beside real cars; connectCars adds it.
  void setGhost(sim::CarSpec spec, std::string what) {
    ghost_ = std::move(spec);
    ghostWhat_ = std::move(what);
  }
  // Finds and connects the real cars (runs the loop until every car had a first attempt).
  std::optional<std::string> connectRealCars();
  void startHost(HostOptions options);
  // --view: the race view's feed and server (docs/view.md); prints the URL. `source` says what
  // the cars are. Non-zero (an error printed) when it cannot serve.
  int startView(const std::string& endpoint, const std::string& source, const char* command);
  // The view's feed without a server (a replay's summary counts laps with it); startView makes
  // it when there is none.
  view::Feed& startFeed(const std::string& source);
  view::Feed* viewFeed() { return feed_.get(); }
  // --humans N and what holds the seats (--gamepads, --keyboard; phones through --view): after
  // the cars and the view are up, before the script. Non-zero (an error printed) when a holder
  // cannot start (no terminal for --keyboard, an unreadable input folder).
  int startSeats(const CarSource& source, const char* command);
  drive::Seats* seats() { return seats_.get(); }
  // --code FOLDER (docs/classroom.md): the classroom, made before the view (which serves its
  // page) and given a desk for each car once the cars are there (addDesks). Non-zero (an error
  // printed) when the folder cannot be used.
  int openClassroom(const std::string& folder, const char* command);
  // A desk for each car of the run: the driver files the race races (car number → file).
  Result<std::map<int, std::string>, std::string> addDesks();
  classroom::Classroom* classroom() { return classroom_.get(); }
  // A spectator (pitwall view): remote cars are read-only, and the end of the run sends them
  // nothing (they are their bridges' cars, not ours).
  void spectate() { spectator_ = true; }
  // The one stop path (docs/safety.md): the script is shut down first (nothing of it runs or
  // commands again), then every car gets its stop as its last command, the record is flushed,
  // the stop frames are given time to reach the cars, real cars are disconnected, and
  // loop().run() ends. Every way out of a run comes here.
  void finish();
  // The loop has returned (every car got its stop): the watchdog goes, so that work done after it
  // (the standings waiting for a lock) is not taken for a stuck loop.
  void loopEnded() { watchdog_.reset(); }
  // The exit status a run ends with: os.exit's or the memory limit's when the script asked for
  // one, else 130 after a signal, else `otherwise`.
  int exitStatus(int otherwise);

 private:
  int connectLocalCars(const char* command);
  int connectRemoteCars(const char* command);
  void catchSignals();
  void suspend();
  void flushRecordPeriodically();

  // The subsystems, in the order they depend on each other: each is destroyed before what is
  // declared above it (the destructor adds nothing but the record's last flush).
  Loop loop_;  // first made, last destroyed: everything below schedules on it
  // The log's time source (a command sets it to loop_'s clock) is reset once everything below
  // has gone, so their last lines keep their times.
  struct ResetLogTime {
    ~ResetLogTime() { log::setTimeSource(nullptr); }
  } resetLogTime_;
  SimSession sim_;
  std::optional<sim::Track> design_;   // --ble --track: the layout the real cars are on
  std::optional<sim::CarSpec> ghost_;  // --ghost: added after the other cars
  std::string ghostWhat_;
  std::unique_ptr<sim::World> ghostWorld_;  // the ghost's world beside real cars'
  bool addGhost();
  AnkiCar& joinSimCar(sim::World& world, const sim::CarSpec& spec, bool ghost);
  bool awaitJoined(const std::vector<const AnkiCar*>& cars);
  Fleet fleet_;
  std::unique_ptr<Recorder> recorder_;
  Subscription recording_;      // the fleet's frames into recorder_ (--record)
  Subscription linkRecording_;  // the cars' links going up and down into recorder_
  std::string raceKey_;         // the phase and title of the race last recorded
  double raceWritten_ = -1e9;   // when (loop seconds)
  bool raceTooLong_ = false;
  std::unique_ptr<ble::Central> central_;  // real cars; after the fleet: its links live there
  // MQTT (docs/mqtt.md): the client, and either remote cars (--mqtt) or the bridge
  std::unique_ptr<MqttClient> mqtt_;
  std::unique_ptr<RemoteCars> remote_;
  std::unique_ptr<MqttBridge> bridge_;
  // human seats (--humans): before the feed, which shows them, and the devices that hold them
  std::unique_ptr<drive::Seats> seats_;
  std::unique_ptr<drive::Gamepads> gamepads_;
  std::unique_ptr<drive::Keyboard> keyboard_;
  // --code: before the view's server (its page) and the Lua world (its driver worlds attach)
  std::unique_ptr<classroom::Classroom> classroom_;
  // the race view: the feed follows the fleet (restores its hooks when destroyed, before it)
  std::unique_ptr<view::Feed> feed_;
  std::unique_ptr<view::Server> server_;
  std::unique_ptr<Reloader> scripts_;  // the Lua world: it holds the seats, the feed and the cars
  CarSource source_;
  // opened from a command line: its --budget, --lua-memory and --handler-errors
  bool limitsFromSource_ = false;
  bool finishing_ = false;
  bool spectator_ = false;
  bool suspending_ = false;  // Ctrl-Z: the cars paused, the process about to stop
  bool outputGone_ = false;  // SIGPIPE on stdout/stderr ended the run (status 141)
  bool interrupted_ = false;
  std::unique_ptr<LagMonitor> lag_;  // real time: says when the loop falls behind
  std::unique_ptr<StopSignals> signals_;
  std::unique_ptr<Watchdog> watchdog_;  // real time: stops the cars when the loop is stuck
};

}  // namespace pitwall::cli
