#include "bindings/script_host.hpp"

#include <cstring>
#include <filesystem>

#include "bindings/car_binding.hpp"
#include "bindings/interrupt.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/misspelled_method.hpp"
#include "bindings/script_file.hpp"
#include "bindings/world.hpp"
#include "engine/core/console.hpp"
#include "engine/core/data_dir.hpp"
#include "engine/core/log.hpp"
#include "engine/drive/seats.hpp"

namespace pitwall {

ScriptHost::ScriptHost(Loop& loop, Fleet& fleet, SimSession* sim, HostOptions options)
    : loop_(loop), fleet_(fleet), sim_(sim), options_(std::move(options)) {
  memory_.limit = options_.memory_limit;
  memory_.driver = options_.driverCar != nullptr;
  L_ = sandbox::newState(memory_);
  if (!L_) throw std::runtime_error("cannot create a Lua state (out of memory)");
  interrupt::watchThisThread(options_.budget.count() > 0);
  *static_cast<ScriptHost**>(lua_getextraspace(L_)) = this;
  try {
    cars_ = std::make_unique<CarBinding>(*this);
    openWorld(*this);
  } catch (...) {
    // a world that does not open (its library does not load) is closed here: no destructor
    // runs for it, and a driver world's failed open must not leak its state
    cars_.reset();
    lua_close(L_);
    L_ = nullptr;
    throw;
  }
  if (!options_.detached) attach();
}

void ScriptHost::attach() {
  if (attached_) return;
  attached_ = true;
  cars_->attach();
  joined_ = fleet_.carJoined.connect([this](AnkiCar& car) { carJoined(car); });
}

void ScriptHost::detach() {
  if (!attached_) return;
  attached_ = false;
  cars_->detach();
  joined_.disconnect();
}

void ScriptHost::carJoined(AnkiCar& car) {
  if (isShutDown()) return;
  cars_->bind(car);
  lua_State* L = L_;
  PITWALL_STACK_CHECK(L, 0, "pitwall.onCar's call (ScriptHost::carJoined)");
  int top = lua_gettop(L);
  lua_getglobal(L, "pitwall");
  if (lua_istable(L, -1) && lua_getfield(L, -1, "onCar") == LUA_TFUNCTION) {
    lua_remove(L, -2);
    cars_->push(L, car);
    call(1, 0, "pitwall.onCar handler", car.label());
  } else {
    lua_settop(L, top);
  }
}

ScriptHost::~ScriptHost() {
  detach();
  // (the tasks' and timers' wake-ups are cancelled by their destructors)
  cars_.reset();  // unhooks the cars before their Lua objects go
  lua_close(L_);
}

void ScriptHost::openSeats(int count) {
  ownSeats_ = std::make_unique<drive::Seats>(loop_, fleet_, count);
}

void ScriptHost::fileLoaded(const std::string& path) {
  loadedFiles_.push_back(path);
  if (onFileLoaded) onFileLoaded(path);
}

void ScriptHost::setLibrary(const std::string& folder) {
  frames_.libraryChunks = "@" + folder + "/pitwall/";
  frames_.libraryFrames = options_.library_frames;
  lua::setFrames(L_, &frames_);
}

ScriptHost& ScriptHost::from(lua_State* L) {
  return **static_cast<ScriptHost**>(lua_getextraspace(L));
}

bool ScriptHost::call(int nargs, int nresults, const char* what, std::string_view who) {
  if (life_ == Life::ShutDown) {
    lua_pop(L_, nargs + 1);
    return false;
  }
  return finishCall(tracedCall(nargs, nresults, interrupt::Kind::Callback, options_.budget), what,
                    who);
}

int ScriptHost::tracedCall(int nargs, int nresults, interrupt::Kind kind,
                           std::chrono::milliseconds budget) {
  const int base = lua_gettop(L_) - nargs;  // the function's slot
  lua_pushcfunction(L_, lua::traceback);
  lua_insert(L_, base);
  const int status = ownBudget() ? lua::protectedOwnCall(L_, nargs, nresults, base, kind, budget)
                                 : lua::protectedCall(L_, nargs, nresults, base, kind, budget);
  lua_remove(L_, base);
  return status;
}

bool ScriptHost::callInteractive(int nargs, int nresults, std::string& error) {
  return protectedCall(nargs, nresults, error, interrupt::Kind::Console, options_.budget);
}

bool ScriptHost::callCapturing(int nargs, int nresults, std::string& error) {
  return protectedCall(nargs, nresults, error, interrupt::Kind::Callback, options_.budget);
}

bool ScriptHost::callLibrary(int nargs, int nresults, std::string& error) {
  // (a budget of 0 is none: a world without one keeps none)
  const auto budget =
      options_.budget.count() == 0 ? options_.budget : std::max(options_.budget, kLibraryBudget);
  return protectedCall(nargs, nresults, error, interrupt::Kind::Callback, budget);
}

bool ScriptHost::protectedCall(int nargs, int nresults, std::string& error, interrupt::Kind kind,
                               std::chrono::milliseconds budget) {
  if (tracedCall(nargs, nresults, kind, budget) == LUA_OK) return true;
  error = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "(error without a message)";
  lua_pop(L_, 1);
  if (memory_.exceeded) error = sandbox::memoryMessage(memory_);
  checkMemory();
  return false;
}

bool ScriptHost::ownCallAboveHandler(int nargs, const char* what, std::string_view who) {
  const int status =
      lua::protectedOwnCall(L_, nargs, 0, -(nargs + 2), interrupt::Kind::Callback, options_.budget);
  if (status == LUA_OK) {
    lua_pop(L_, 1);  // the handler
    return true;
  }
  return failedAboveHandler(status, what, who);
}

bool ScriptHost::failedAboveHandler(int status, const char* what, std::string_view who) {
  lua_remove(L_, -2);  // the handler, under the error
  return finishCall(status, what, who);
}

bool ScriptHost::finishCall(int status, const char* what, std::string_view who) {
  if (status == LUA_OK) return true;
  std::string message = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "(error without a message)";
  lua_pop(L_, 1);
  if (memory_.exceeded) {
    checkMemory();
    return false;
  }
  std::string where = what;
  if (!who.empty()) where.append(" of ").append(who);
  reportError(where, message);
  return false;
}

void ScriptHost::requestExit(int status) {
  if (ownBudget())
    return driverFailed("it called os.exit(" + std::to_string(status) +
                        "): a driver cannot end the run");
  if (!exitStatus_) exitStatus_ = status;
  if (!stopRequested_) return requestStop();
  // pitwall.stop() came first: the stop path is under way, and takes the exit status from here
}

void ScriptHost::shutDown() {
  if (isShutDown()) return;
  life_ = Life::ShutDown;
  errors_.flush();  // counts of errors not yet logged: none is lost
  // The handlers stay hooked until the world closes (this may run inside one of them); call()
  // turns every call into Lua away from now on.
  tasks_.shutDown();
  timers_.shutDown();
  auto hooks = std::move(atShutDown_);
  for (auto& fn : hooks) fn();
}

void ScriptHost::lastWords() {
  if (life_ != Life::ShutDown) return;
  lua_State* L = L_;
  PITWALL_STACK_CHECK(L, 0, "the last words (ScriptHost::lastWords)");
  int top = lua_gettop(L);
  lua_getglobal(L, "pitwall");
  if (lua_istable(L, -1) && lua_getfield(L, -1, "_lastWords") == LUA_TFUNCTION) {
    // once: a second call finds the field gone
    lua_pushnil(L);
    lua_setfield(L, -3, "_lastWords");
    life_ = Life::LastWords;
    call(0, 0, "the end of the run (pitwall._lastWords)");
    life_ = Life::ShutDown;
  }
  lua_settop(L, top);
}

void ScriptHost::atShutDown(std::function<void()> fn) {
  if (isShutDown())
    fn();
  else
    atShutDown_.push_back(std::move(fn));
}

void ScriptHost::requestStop() {
  if (ownBudget()) {
    if (driverFailure_.empty())
      driverFailed(
          "it called pitwall.stop: a driver cannot end the race (its `update` decides "
          "its car's speed; the race director ends the race)");
    return;
  }
  if (stopRequested_) return;
  stopRequested_ = true;
  if (onStopRequested) onStopRequested();
}

Result<bool, std::string> ScriptHost::startLoaded() {
  tasks_.spawn(L_, "main chunk", true);
  return true;
}

Result<bool, std::string> ScriptHost::loadFile(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // The script's own folder joins the front of the require path (as messages show it: its
  // modules are named relative to the current folder too).
  // (Not a driver world's: it requires the shipped library only, docs/drivers.md.)
  fs::path folder = fs::path(script_file::shownPath(path)).parent_path();
  if (!ownBudget()) prependRequirePath(L_, {folder.empty() ? std::string(".") : folder.string()});
  if (auto loaded = script_file::load(L_, path); !loaded) return loaded;
  loadedFiles_.push_back(fs::absolute(path, ec).lexically_normal().string());
  return true;
}

Result<bool, std::string> ScriptHost::startLoadedFile(StartMode mode) {
  if (mode == StartMode::Run) return startLoaded();
  std::optional<std::string> error;
  trialError_ = &error;
  auto started = startLoaded();
  trialError_ = nullptr;
  if (started && error) return Unexpected{*error};
  return started;
}

Result<bool, std::string> ScriptHost::startFile(const std::string& path, StartMode mode) {
  if (auto loaded = loadFile(path); !loaded) return loaded;
  return startLoadedFile(mode);
}

Result<bool, std::string> ScriptHost::loadString(const std::string& code,
                                                 const std::string& chunkname) {
  if (luaL_loadbufferx(L_, code.data(), code.size(), ("@" + chunkname).c_str(), "t") != LUA_OK) {
    std::string err = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "cannot load the script";
    lua_pop(L_, 1);
    return Unexpected{err};
  }
  return true;
}

Result<bool, std::string> ScriptHost::startString(const std::string& code,
                                                  const std::string& chunkname) {
  if (auto loaded = loadString(code, chunkname); !loaded) return loaded;
  return startLoaded();
}

void ScriptHost::mainEnded(const std::string& where, const std::string& error) {
  main_ = error.empty() ? Main::Returned : Main::Failed;
  if (trialError_ && !error.empty()) {  // a trial start gives the error back instead
    *trialError_ = error;
    return;
  }
  if (!error.empty()) {
    reportError(where, error);
    // The script died: the run ends and its cars are stopped (DESIGN.md, "keeps cars safe").
    requestStop();
  }
  if (options_.test_mode) requestStop();  // a scenario ends with its main chunk
}

void ScriptHost::driverFailed(const std::string& why) {
  if (!driverFailure_.empty() || !options_.driverCar) return;
  driverFailure_ = why;
  // Its car first: the stop goes out before anything else runs (AnkiCar::stop, as any stop).
  (void)options_.driverCar->stop();
  shutDown();
  if (options_.driverFailed) options_.driverFailed(why);
}

}  // namespace pitwall
