#pragma once
// A driver world (docs/drivers.md): one driver file, in a Lua world of its own, driving one car
// for the race director of the run's world. The file returns a driver — a class ({new}) or a
// driver ({update}), the race library's shape — and the director calls its methods through
// call(): the race's state copied in as plain data, the method run under the world's own budget.
//
// The world is a ScriptHost made with HostOptions::driverCar: it commands only its car, reads
// no file, requires the shipped library only, and its first failure (an error, its budget, its
// memory cap, os.exit, pitwall.stop, a file that does not load) stops its car and shuts it down
// — failure() says why; the run goes on. In real time it also fails when its calls take more
// than its share of the loop (DriverLimits::share: on average, half its budget), so a driver that
// uses most of its budget in every call cannot starve the others. A good save (reload(), or
// --watch) makes a new world; the director then takes the car back (scripts/pitwall/drivers.lua,
// drivers.world).
#include <lua.hpp>

#include <deque>
#include <memory>
#include <string>

#include "bindings/script_host.hpp"
#include "engine/classroom/classroom.hpp"
#include "engine/core/file_watch.hpp"

namespace pitwall {

// A desk's driver of the code page's classroom too (engine/classroom): while its file is a desk's
// and its session on, a student's save reloads it (trySave: tryReload) and the teacher's reset
// starts it again (restart: reload).
class DriverWorld : public classroom::DeskDriver {
 public:
  // `race` is the director's world (its loop, fleet, seed and traceback style are the world's
  // too); `file` the driver file. Loads it (failure() says whether it did).
  DriverWorld(ScriptHost& race, AnkiCar& car, std::string file, DriverLimits limits);
  ~DriverWorld() override;
  DriverWorld(const DriverWorld&) = delete;
  DriverWorld& operator=(const DriverWorld&) = delete;

  // Calls the driver's `method` (start, update, finish, waiting) in the world with the values from
  // index `first` of `from` (a thread of the director's world) to its top copied in (what
  // drivers.world sends: the car, its limits, the period, the race's phase and standings, the map
  // once). False when the world has failed, now or before.
  bool call(lua_State* from, const char* method, int first);
  // Loads the file again into a new world: the old one goes (its car keeps its last speed until
  // the director calls the new one). False, and failure() set, when the new one fails.
  bool reload();
  // Loads the file again into a new world that replaces the one driving only when it loads and
  // sets its driver up (the code editor's save, issue 39): true, its version +1 (the director
  // starts it, and a driver that was out is back); else false, `why` the engine's sentence
  // ("alice.lua:3: …"), and the world driving goes on as it was.
  bool tryReload(std::string& why);
  // Shuts the world down for good (its session ended): it follows no car any more and is freed on
  // a later turn of the loop; later calls and reloads do nothing. Its car is left as it is.
  void close();

  const std::string& failure() const { return failure_; }
  // the classroom's (classroom::DeskDriver)
  bool trySave(std::string& why) override { return tryReload(why); }
  bool restart(std::string& why) override;
  int drivingVersion() const override { return version_; }
  std::string whyOut() const override { return failure_; }
  const std::string& file() const { return file_; }
  AnkiCar& car() { return car_; }
  int version() const { return version_; }         // 1 for the first world, +1 for each reload
  double cpuSeconds() const { return cpuTotal_; }  // what its calls used, every version's

 private:
  void fail(const std::string& why);
  // A new world of the file with its driver set up, or nullptr and `why`. Its failures go to
  // fail() once *live is true; before, to `why`.
  std::unique_ptr<ScriptHost> open(std::string& why, const std::shared_ptr<bool>& live);
  // The world now (if any) retired: freed on a later turn (it may be on the stack).
  void retire();
  // The CPU time a call used: failed past its share (real time, DriverLimits::share).
  void charge(double cpu);
  void watch();
  void leaveDesk();

  ScriptHost& race_;
  AnkiCar& car_;
  std::string file_;
  std::string name_;  // the file's name without its folder, as the log and errors say it
  DriverLimits limits_;
  std::unique_ptr<ScriptHost> host_;
  // Worlds replaced or failed: a world may be on the stack when it goes (it failed inside its
  // own call), so it is freed on a later turn of the loop.
  std::vector<std::unique_ptr<ScriptHost>> retired_;
  Loop::TimerId sweep_ = 0;
  std::string failure_;
  int version_ = 0;
  bool closed_ = false;
  std::deque<double> spent_;  // the CPU time of its last calls (DriverLimits::shareCalls)
  double spentSum_ = 0, cpuTotal_ = 0;
  std::unique_ptr<FileWatch> watch_;
  classroom::Classroom* desk_ = nullptr;  // the classroom whose desk it drives, if any
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace pitwall
