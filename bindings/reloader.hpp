#pragma once
// One script run as a sequence of versions (hot reload, docs/hot-reload.md). Each version is a
// fresh Lua world (a ScriptHost) over the same cars, as Hammerspoon reloads: nothing of an old
// version can linger. A new version takes over only once it has started cleanly; until then the
// old one keeps running and keeps its cars' events.
//
// A reload is one step on the engine's loop: no car event can arrive while it runs. Events that
// come meanwhile wait in the loop and reach the new version.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/core/file_watch.hpp"

namespace pitwall {

class Reloader {
 public:
  // Makes the first Lua world, attached to the cars, with no script yet.
  Reloader(Loop& loop, Fleet& fleet, SimSession* sim, HostOptions options);
  ~Reloader();
  Reloader(const Reloader&) = delete;
  Reloader& operator=(const Reloader&) = delete;

  ScriptHost& host() { return *current_; }
  const std::string& script() const { return script_; }

  // Runs SCRIPT in the current world (its first version). "FILE:LINE: message" when it does not
  // load.
  Result<bool, std::string> start(const std::string& script);
  // Loads the script again as a new version (docs/hot-reload.md has the order of events). On
  // failure the running version carries on untouched and the error says why.
  Result<bool, std::string> reload(const std::vector<std::string>& changed = {});
  // A scenario's script under test (pitwall.sim.script, sim.reload): the script is source text
  // named `name`, or from now on the file `path`.
  struct Source {
    std::string code;
    std::string name;
  };
  Result<bool, std::string> startSource(const Source& source);
  Result<bool, std::string> reloadSource(const Source& source);
  Result<bool, std::string> reloadFile(const std::string& path);
  // Reloads whenever one of the script's files is saved: the script and every module it loaded
  // from disk with require. Failures are logged; the running version carries on.
  Result<bool, std::string> watch(Duration debounce = std::chrono::milliseconds(100));

  // A script that dies (its main chunk fails) normally ends the run; with this set, its cars are
  // stopped and the run waits for a fix (--watch, --repl).
  void keepRunningOnError(bool keep) { keepRunning_ = keep; }

  // The run is ending (docs/safety.md): the current version shuts down (ScriptHost::shutDown)
  // and no save starts another.
  void shutDown();
  // Then, once the cars are stopped: the current version's last words (ScriptHost::lastWords).
  void lastWords() { current_->lastWords(); }

  // pitwall.stop(), or the script died and nothing keeps the run going.
  std::function<void()> onStopRequested;
  // A new version took over (the REPL evaluates in host() from now on).
  std::function<void(ScriptHost&)> onNewVersion;

  struct Stats {
    int reloads = 0;   // versions that took over
    int failures = 0;  // versions refused
    Duration last{};   // how long the last successful reload took (the engine's part)
  };
  const Stats& stats() const { return stats_; }

 private:
  std::unique_ptr<ScriptHost> makeWorld(bool detached);
  void hookStop(ScriptHost& host);
  void watchFile(const std::string& path);
  void changed(const std::vector<std::string>& paths);
  Result<bool, std::string> reloadFrom(const std::vector<std::string>& changed,
                                       const Source* source);

  Loop& loop_;
  Fleet& fleet_;
  SimSession* sim_;
  HostOptions options_;
  std::string script_;
  std::unique_ptr<ScriptHost> current_;
  std::unique_ptr<FileWatch> watch_;
  std::vector<std::string> watched_;
  bool keepRunning_ = false;
  bool shutDown_ = false;
  Stats stats_;
};

// Copies pitwall.persist of `from` into a new table on top of `to`'s stack: plain data (nil,
// booleans, numbers, strings, tables — shared and cyclic ones kept so) and cars (as `to`'s own
// objects for the same cars). Anything else (functions, coroutines, other userdata, metatables)
// cannot cross into another Lua world: it is left out and named in `dropped`
// ("pitwall.persist.onLap (a function)").
void copyPersist(ScriptHost& from, ScriptHost& to, std::vector<std::string>& dropped);
// The library's own state (a race in progress): pitwall._saveCarried() of `from`, copied the same
// way onto `to`'s stack, but quietly: its functions and metatables stay behind by design (the
// new version's modules bring their own and take the data up again).
void copyCarried(ScriptHost& from, ScriptHost& to);

}  // namespace pitwall
