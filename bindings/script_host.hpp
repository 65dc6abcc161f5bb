#pragma once
// The Lua world of one run: the state, the `pitwall` module, car objects, its tasks and timers on
// the engine clock (bindings/tasks.hpp, bindings/timers.hpp), the world's life (attach, shut
// down, last words), and the one protected-call path every call into Lua goes through.
//
// Errors: an error in a callback is reported (bindings/error_report.hpp: to pitwall.onError, or
// the log with a traceback) and the run carries on; in test mode it fails the scenario instead.
#include <lua.hpp>

#include <nlohmann/json_fwd.hpp>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bindings/error_report.hpp"
#include "bindings/interrupt.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/protected_call.hpp"
#include "bindings/sandbox.hpp"
#include "bindings/tasks.hpp"
#include "bindings/timers.hpp"
#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/world.hpp"

namespace pitwall {

class CarBinding;
namespace drive {
class Seats;
}
namespace view {
class Feed;
}
namespace classroom {
class Classroom;
}

// The simulator as scripts see it (pitwall.sim): present for simulator runs and scenario tests.
struct SimSession {
  std::unique_ptr<sim::World> world;
  std::uint64_t seed = 1;
};

// A car whose script keeps failing slows to a stop (docs/safety.md): `count` errors of one
// handler (or of one event's listeners) of a car within `window` seconds stop that car, and the
// world that failed commands it no more; the race goes on for the others. A hot reload (a new
// world) may drive it again. count 0: never stop (--handler-errors 0).
struct HandlerErrorLimit {
  int count = 5;
  double window = 10.0;
};

// What each driver world may use (docs/drivers.md): its memory cap in bytes, the CPU time of
// one call (its own budget, not the race director's), and in real time its share of the loop —
// the CPU time its last `shareCalls` calls may take on average, as a fraction of the budget (0:
// no share): a call may take up to the budget now and then, not every time — and whether its
// file is watched for saves (--watch).
struct DriverLimits {
  std::size_t memory = std::size_t{64} << 20;
  std::chrono::milliseconds budget{50};
  double share = 0.5;
  int shareCalls = 10;
  bool watch = false;
};

struct HostOptions {
  bool test_mode = false;      // callback errors fail the run; `expect` helpers loaded
  bool library_frames = true;  // tracebacks list the library's frames (lua::Frames)
  // This world's limits (docs/safety.md): its memory cap in bytes (--lua-memory; 0: none) and
  // the CPU time each callback may take (--budget; 0: none). Worlds side by side may differ.
  std::size_t memory_limit = sandbox::kDefaultMemoryLimit;
  std::chrono::milliseconds budget = interrupt::kDefaultBudget;
  HandlerErrorLimit handler_errors;        // --handler-errors, --handler-errors-window
  std::uint64_t seed = 1;                  // math.randomseed
  std::vector<std::string> library_paths;  // extra folders searched by require
  std::string results;                     // --results FILE (pitwall.resultsFile), empty: none
  // Made detached: the cars' events reach this world only after attach() (a hot reload's new
  // version, until it has started).
  bool detached = false;
  // The race view's feed (--view): pitwall.view reports to it; none: pitwall.view does nothing.
  view::Feed* view = nullptr;
  // --ble --track FILE: the layout of the pieces the real cars are on; pitwall.piece knows its
  // custom pieces' shapes (docs/tracks.md). With the simulator, its own track serves.
  const sim::Track* design = nullptr;
  // --humans: the seats of human drivers (pitwall.seats); none: no seats.
  drive::Seats* seats = nullptr;
  // --record: the race as pitwall.view.race reports it, into the record (for a replay's view);
  // unset: not recorded. pitwall.view.recording says whether it is set.
  std::function<void(const nlohmann::json& race)> recordRace;
  // The standings database of the run (--db; docs/league.md "Standings"): a race's results as
  // pitwall.keepResults hands them (engine/standings/race_json.hpp), kept; returns the sentence
  // when they were not written now (held, or saved beside the database). Unset: nothing is kept.
  std::function<std::optional<std::string>(const nlohmann::json& race)> keepRace;
  // A driver world (docs/drivers.md, bindings/driver_world.hpp): `driverCar` is the one car it
  // may command (every other car's commands are refused, and its own cannot be disconnected);
  // its library reaches no file, robot, simulator control or the run's results; its budget is
  // its own even when the race director calls it; and its first failure — an error, its budget,
  // its memory cap, os.exit, pitwall.stop — goes to `driverFailed` (once) and shuts the world
  // down instead of ending the run. nullptr: a run's world.
  AnkiCar* driverCar = nullptr;
  std::function<void(const std::string& why)> driverFailed;
  // --driver CAR=FILE (pitwall.driverFiles: a race's driver of car number CAR is FILE, in a world
  // of its own) and those worlds' limits (--driver-memory, --driver-budget, --watch).
  std::map<int, std::string> driverFiles;
  DriverLimits driverLimits;
  // --code: the classroom of the view's code page (docs/classroom.md): a driver world of a desk's
  // file attaches to its desk (a save reloads it), and pitwall.classroom is there.
  classroom::Classroom* classroom = nullptr;
  // --league-final: the league's final this run races (pitwall.final, read by the shipped
  // scripts/pitwall/league_final.lua; docs/league.md "The final"); driverFiles holds its files.
  struct LeagueFinal {
    std::string title;
    int laps = 5;
    std::int64_t league = 0;
    std::vector<std::string> drivers;  // pole first: car 1's, car 2's, …
  };
  std::optional<LeagueFinal> leagueFinal;
};

class ScriptHost {
 public:
  ScriptHost(Loop& loop, Fleet& fleet, SimSession* sim, HostOptions options);
  ~ScriptHost();
  ScriptHost(const ScriptHost&) = delete;
  ScriptHost& operator=(const ScriptHost&) = delete;

  lua_State* state() { return L_; }
  Loop& loop() { return loop_; }
  Fleet& fleet() { return fleet_; }
  SimSession* sim() { return sim_; }
  CarBinding& cars() { return *cars_; }
  Tasks& tasks() { return tasks_; }
  const Tasks& tasks() const { return tasks_; }
  Timers& timers() { return timers_; }
  const HostOptions& options() const { return options_; }
  // The seats of human drivers: the run's (--humans), or the script's own in the simulator
  // (sim.openSeats); nullptr: none.
  drive::Seats* seats() { return options_.seats ? options_.seats : ownSeats_.get(); }
  void openSeats(int count);

  // Loads SCRIPT and starts its main chunk as a task (so it may pitwall.sleep). A script that
  // does not load gives "FILE:LINE: message". Its folder joins the require path.
  // As a Trial, an error in the main chunk before its first sleep is returned instead of being
  // reported, and does not stop the run (a hot reload then keeps the old version).
  enum class StartMode { Run, Trial };
  Result<bool, std::string> startFile(const std::string& path, StartMode mode = StartMode::Run);
  // The two halves of startFile: compile SCRIPT and leave its chunk on the stack (a hot reload
  // compiles before it tells the running version anything), then start that chunk.
  Result<bool, std::string> loadFile(const std::string& path);
  Result<bool, std::string> startLoadedFile(StartMode mode);
  // loadFile for a chunk of text named `chunkname` (a scenario's script under test).
  Result<bool, std::string> loadString(const std::string& code, const std::string& chunkname);
  // Same for a chunk of text (tests, benchmarks).
  Result<bool, std::string> startString(const std::string& code, const std::string& chunkname);
  bool mainFinished() const { return main_ != Main::Running; }
  bool mainFailed() const { return main_ == Main::Failed; }

  // Calls the function under the top `nargs` values with the traceback handler. On error the
  // failure is reported as happening in `what` of `who`, when given: "onPosition handler" of
  // "car 1 (skull)". Returns true when the call succeeded; results are left on the stack. Builds
  // no string unless the call fails: this is the hot path of every event (a caller keeps its
  // label made, as the car binding does).
  bool call(int nargs, int nresults, const char* what, std::string_view who = {});
  // The same with no results, for a caller that pushed lua::traceback itself right under the
  // function (the event hot path: no stack rotation). Pops the handler too.
  bool callAboveHandler(int nargs, const char* what, std::string_view who = {}) {
    if (life_ != Life::Running) {
      lua_pop(L_, nargs + 2);
      return false;
    }
    if (ownBudget()) [[unlikely]]
      return ownCallAboveHandler(nargs, what, who);
    const int status =
        lua::protectedCall(L_, nargs, 0, -(nargs + 2), interrupt::Kind::Callback, options_.budget);
    if (status == LUA_OK) {
      lua_pop(L_, 1);  // the handler
      return true;
    }
    return failedAboveHandler(status, what, who);
  }
  // A chunk typed at the REPL (the function under the top `nargs` values): Ctrl-C interrupts
  // it, the callback budget does not apply. On failure returns false with the message and
  // traceback in `error` (not reported: the REPL prints it). Results are left on the stack.
  bool callInteractive(int nargs, int nresults, std::string& error);
  // The same for a call from the engine that wants the error rather than a report (a hot
  // reload's onReload hook): budgeted like any callback.
  bool callCapturing(int nargs, int nresults, std::string& error);
  // The same for the engine's own Lua library as the world opens (require 'pitwall.core'): a
  // budget of its own, kLibraryBudget or the world's when larger — a slow machine (a QEMU guest
  // under load, a small board) takes more than a callback's 100 ms (a driver world's 50 ms) to
  // compile and run it, and that is no script's fault. A library that never loads still fails.
  static constexpr std::chrono::milliseconds kLibraryBudget{5000};
  bool callLibrary(int nargs, int nresults, std::string& error);

  // Routes the cars' events (and cars that join) into this world; detach() hands them back.
  void attach();
  void detach();
  bool attached() const { return attached_; }

  // The files this world loaded from disk: the script and every module found by require.
  const std::vector<std::string>& loadedFiles() const { return loadedFiles_; }
  std::function<void(const std::string& path)> onFileLoaded;
  // require found a module file (bindings/world.cpp): recorded, and onFileLoaded told.
  void fileLoaded(const std::string& path);
  // The shipped library's folder, as require finds it: its chunks are the library's frames in
  // this world's tracebacks and blame (lua::Frames).
  void setLibrary(const std::string& folder);
  // Reports a script error (ErrorReport::report): to pitwall.onError if set, else the log; in
  // test mode, a failure.
  void reportError(const std::string& where, const std::string& message) {
    errors_.report(where, message);
  }

  // pitwall.stop() and failures end the run through this.
  std::function<void()> onStopRequested;
  void requestStop();
  bool stopRequested() const { return stopRequested_; }
  // os.exit(code) from the script or the REPL: the run ends through the stop path with this exit
  // status. Also set (to 1) when the script reached its memory limit.
  void requestExit(int status);
  const std::optional<int>& exitStatus() const { return exitStatus_; }

  // The run is ending (docs/safety.md): nothing of this world runs again — no timer, task, event
  // handler or callback — except a chunk typed at the REPL. Final.
  void shutDown();
  bool isShutDown() const { return life_ != Life::Running; }
  // Runs `fn` when this world shuts down (what it started that must end with it), or at once
  // when it already has.
  void atShutDown(std::function<void()> fn);
  // After the shutdown and the cars' stops: the Lua library's last words, once
  // (pitwall._lastWords: a race cut short prints its final table and writes its results). The
  // one call into Lua after shutDown, budgeted like any callback; the cars take no command by
  // then (AnkiCar::halt) and no timer or task can start.
  void lastWords();
  // The memory this world's allocations hold now, and its cap (sandbox.hpp).
  const sandbox::Memory& memory() const { return memory_; }
  // The bytes the engine keeps for this world outside Lua, charged to its cap (Memory::outside).
  void chargeOutside(std::size_t bytes) { memory_.outside = bytes; }
  // After a failed call into Lua: when the memory limit was reached, says so once and ends the
  // run (exit status 1).
  void checkMemory() { errors_.checkMemory(); }
  // How the script's main chunk ended (Tasks): `error` empty when it returned. A failure ends
  // the run (its cars are stopped), or is handed back by a trial start; a scenario ends with it.
  void mainEnded(const std::string& where, const std::string& error);
  // In test mode: the first failure (error in a task or callback, failed expectation).
  const std::optional<std::string>& failure() const { return errors_.failure(); }
  int errorCount() const { return errors_.count(); }

  static ScriptHost& from(lua_State* L);

  // A driver world (HostOptions::driverCar): its car, and whether it failed (why, once).
  AnkiCar* driverCar() const { return options_.driverCar; }
  bool ownBudget() const { return options_.driverCar != nullptr; }
  const std::string& driverFailure() const { return driverFailure_; }
  // A driver world's failure: said once to HostOptions::driverFailed, its car stopped, the world
  // shut down. The run goes on.
  void driverFailed(const std::string& why);

 private:
  friend class ErrorReport;  // counts a car's handler errors towards its stop (cars_)
  void carJoined(AnkiCar& car);
  bool protectedCall(int nargs, int nresults, std::string& error, interrupt::Kind kind,
                     std::chrono::milliseconds budget);
  bool finishCall(int status, const char* what, std::string_view who);
  // callAboveHandler's error path, out of line: the error over the handler.
  bool failedAboveHandler(int status, const char* what, std::string_view who);
  // callAboveHandler in a driver world (its budget its own), out of line.
  bool ownCallAboveHandler(int nargs, const char* what, std::string_view who);
  Result<bool, std::string> startLoaded();
  // Calls the function under the top `nargs` values with the traceback handler under it (gone
  // after): lua::protectedCall's status, the error or the results on the stack.
  int tracedCall(int nargs, int nresults, interrupt::Kind kind, std::chrono::milliseconds budget);

  Loop& loop_;
  Fleet& fleet_;
  SimSession* sim_;
  HostOptions options_;
  sandbox::Memory memory_;  // before L_: the state's allocator counts in it until lua_close
  lua::Frames frames_;      // before L_: its tracebacks read it until lua_close
  lua_State* L_ = nullptr;
  std::unique_ptr<CarBinding> cars_;
  Tasks tasks_{*this};
  Timers timers_{*this};
  // The world's life: running; shut down (nothing of it runs again); saying its last words (the
  // one call let through after the shutdown).
  enum class Life { Running, ShutDown, LastWords } life_ = Life::Running;
  enum class Main { Running, Returned, Failed } main_ = Main::Running;  // its main chunk
  bool stopRequested_ = false;  // pitwall.stop() or a failure asked the run to end
  std::optional<int> exitStatus_;
  ErrorReport errors_{*this};
  bool attached_ = false;
  Subscription joined_;  // Fleet::carJoined, while attached
  // While a trial start runs: where its main chunk's error goes (instead of being reported).
  std::optional<std::string>* trialError_ = nullptr;
  std::vector<std::string> loadedFiles_;
  std::vector<std::function<void()>> atShutDown_;
  std::unique_ptr<drive::Seats> ownSeats_;  // sim.openSeats: after L_, which reads them
  std::string driverFailure_;               // a driver world's first failure (driverFailed)
};

}  // namespace pitwall
