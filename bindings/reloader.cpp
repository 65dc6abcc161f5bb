#include "bindings/reloader.hpp"

#include <cstdio>
#include <filesystem>

#include "bindings/car_binding.hpp"
#include "bindings/lua_args.hpp"
#include "bindings/world_copy.hpp"
#include "engine/core/log.hpp"

namespace pitwall {

void copyPersist(ScriptHost& from, ScriptHost& to, std::vector<std::string>& dropped) {
  lua_State* F = from.state();
  lua_State* T = to.state();
  int fromTop = lua_gettop(F);
  lua::WorldCopy copier(F, T, dropped);
  copier.openMemo();
  lua_getglobal(F, "pitwall");
  bool copied = lua_istable(F, -1) && lua_getfield(F, -1, "persist") == LUA_TTABLE &&
                copier.copy(-1, "pitwall.persist", 0);
  if (!copied) lua_newtable(T);
  copier.closeMemo();
  lua_settop(F, fromTop);
}

void copyCarried(ScriptHost& from, ScriptHost& to) {
  lua_State* F = from.state();
  lua_State* T = to.state();
  int fromTop = lua_gettop(F);
  std::vector<std::string> dropped;
  lua::WorldCopy copier(F, T, dropped, true);
  copier.openMemo();
  lua_getglobal(F, "pitwall");
  int pitwall = lua_gettop(F);
  bool copied = false;
  if (lua_istable(F, pitwall) && lua_getfield(F, pitwall, "_saveCarried") == LUA_TFUNCTION) {
    if (from.call(0, 1, "pitwall (carrying the library's state into the new version)") &&
        lua_istable(F, -1)) {
      // Then the user code the carriers queued (drivers' handovers), each in a call of its own
      // with a budget of its own: it fills in the table above, or fails alone.
      for (lua_Integer i = 1; i <= 100000; ++i) {
        if (lua_getfield(F, pitwall, "_runHandover") != LUA_TFUNCTION) {
          lua_pop(F, 1);
          break;
        }
        lua_pushinteger(F, i);
        if (!from.call(1, 1, "pitwall (handing over into the new version)")) continue;
        bool more = lua_toboolean(F, -1);
        lua_pop(F, 1);
        if (!more) break;
      }
      copied = copier.copy(-1, "carried", 0);
    } else {
      log::error("reload",
                 "the library's state could not be carried into the new version (see "
                 "the error above): a race under way starts anew there");
    }
  }
  if (!copied) lua_newtable(T);
  copier.closeMemo();
  lua_settop(F, fromTop);
}

Reloader::Reloader(Loop& loop, Fleet& fleet, SimSession* sim, HostOptions options)
    : loop_(loop), fleet_(fleet), sim_(sim), options_(std::move(options)) {
  current_ = makeWorld(false);
}

Reloader::~Reloader() {
  watch_.reset();
  current_.reset();
}

std::unique_ptr<ScriptHost> Reloader::makeWorld(bool detached) {
  HostOptions options = options_;
  options.detached = detached;
  auto host = std::make_unique<ScriptHost>(loop_, fleet_, sim_, std::move(options));
  host->onFileLoaded = [this](const std::string& path) { watchFile(path); };
  hookStop(*host);
  return host;
}

void Reloader::hookStop(ScriptHost& host) {
  host.onStopRequested = [this, &host] {
    if (&host != current_.get()) return;  // on trial: reload() acts on it once it took over
    if (keepRunning_ && host.mainFailed() && !host.exitStatus()) {
      fleet_.stopAll();
      log::warn("pitwall",
                "the script stopped with an error; its cars are stopped. Save a fix and it "
                "reloads" +
                    std::string(watch_ ? "" : " (with --watch)"));
      return;
    }
    if (onStopRequested) onStopRequested();
  };
}

Result<bool, std::string> Reloader::start(const std::string& script) {
  script_ = script;
  return current_->startFile(script);
}

Result<bool, std::string> Reloader::startSource(const Source& source) {
  script_ = source.name;
  if (auto loaded = current_->loadString(source.code, source.name); !loaded) return loaded;
  return current_->startLoadedFile(ScriptHost::StartMode::Run);
}

Result<bool, std::string> Reloader::reload(const std::vector<std::string>& changed) {
  return reloadFrom(changed, nullptr);
}

Result<bool, std::string> Reloader::reloadSource(const Source& source) {
  script_ = source.name;
  return reloadFrom({source.name}, &source);
}

Result<bool, std::string> Reloader::reloadFile(const std::string& path) {
  script_ = path;
  return reloadFrom({path}, nullptr);
}

Result<bool, std::string> Reloader::reloadFrom(const std::vector<std::string>& changed,
                                               const Source* source) {
  auto began = std::chrono::steady_clock::now();
  auto refuse = [this](std::string error) -> Result<bool, std::string> {
    ++stats_.failures;
    return Unexpected{std::move(error)};
  };
  if (script_.empty()) return refuse("there is no script to reload");
  auto next = makeWorld(true);

  // 1. It must compile before the running version hears of it. The chunk stays on the new
  // world's stack until step 4 runs it.
  lua_State* N = next->state();
  auto loaded = source ? next->loadString(source->code, source->name) : next->loadFile(script_);
  if (!loaded) return refuse(loaded.error());

  // 2. The running version's last word: pitwall.onUnload(persist).
  ScriptHost& old = *current_;
  lua_State* O = old.state();
  int top = lua_gettop(O);
  lua_getglobal(O, "pitwall");
  if (lua_istable(O, -1) && lua_getfield(O, -1, "onUnload") == LUA_TFUNCTION) {
    lua_getfield(O, -2, "persist");
    old.call(1, 0, "pitwall.onUnload");
  }
  lua_settop(O, top);

  // 3. What survives: pitwall.persist, copied into the new world.
  std::vector<std::string> dropped;
  copyPersist(old, *next, dropped);
  lua_getglobal(N, "pitwall");
  lua_insert(N, -2);
  lua_setfield(N, -2, "persist");
  lua_pushinteger(N, stats_.reloads + 1);
  lua_setfield(N, -2, "reloads");
  lua_pop(N, 1);
  for (const auto& d : dropped)
    log::warn("reload", d + " cannot cross into the new version; left out");
  // 3b. What the library carries over (a race in progress, docs/hot-reload.md "Races").
  copyCarried(old, *next);
  lua_getglobal(N, "pitwall");
  lua_insert(N, -2);
  lua_setfield(N, -2, "_carried");
  lua_pop(N, 1);

  // 4. The new version starts, up to its first sleep; then its pitwall.onReload(persist, info).
  if (auto started = next->startLoadedFile(ScriptHost::StartMode::Trial); !started)
    return refuse(started.error());
  lua_getglobal(N, "pitwall");
  if (lua_getfield(N, -1, "onReload") == LUA_TFUNCTION) {
    lua_getfield(N, -2, "persist");
    lua_createtable(N, 0, 2);
    lua::setInteger(N, "reloads", stats_.reloads + 1);
    lua_createtable(N, static_cast<int>(changed.size()), 0);
    for (std::size_t i = 0; i < changed.size(); ++i) {
      lua_pushlstring(N, changed[i].data(), changed[i].size());
      lua_rawseti(N, -2, static_cast<lua_Integer>(i + 1));
    }
    lua_setfield(N, -2, "files");
    std::string error;
    bool ok = next->callCapturing(2, 0, error);
    lua_pop(N, 1);
    if (!ok) return refuse("pitwall.onReload: " + error);
  } else {
    lua_pop(N, 2);
  }

  // 5. The swap: the cars' events go to the new version from the next one on; the old
  // version's timers, tasks and handlers die with its Lua world.
  old.detach();
  next->attach();
  std::unique_ptr<ScriptHost> retired = std::move(current_);
  current_ = std::move(next);
  ++stats_.reloads;
  stats_.last = std::chrono::steady_clock::now() - began;
  retired.reset();
  if (onNewVersion) onNewVersion(*current_);
  // A pitwall.stop() of the new version's first run was held until it took over.
  if (current_->stopRequested() && !current_->mainFailed() && onStopRequested) onStopRequested();
  return true;
}

Result<bool, std::string> Reloader::watch(Duration debounce) {
  try {
    watch_ = std::make_unique<FileWatch>(loop_, debounce);
  } catch (const std::exception& e) {
    return Unexpected{std::string("cannot watch the script's files: ") + e.what()};
  }
  watch_->onChange = [this](const std::vector<std::string>& paths) { changed(paths); };
  if (!script_.empty()) {
    if (auto added = watch_->add(script_); !added) return Unexpected{added.error()};
  }
  for (const auto& f : current_->loadedFiles()) watchFile(f);
  return true;
}

void Reloader::watchFile(const std::string& path) {
  if (!watch_) return;
  for (const auto& w : watched_)
    if (w == path) return;
  watched_.push_back(path);
  if (auto added = watch_->add(path); !added)
    log::warn("reload", "not watching " + path + ": " + added.error());
}

void Reloader::shutDown() {
  shutDown_ = true;  // no version after this one (the watch itself lives on, idle)
  current_->shutDown();
}

void Reloader::changed(const std::vector<std::string>& paths) {
  if (shutDown_) return;
  std::string names;
  for (const auto& p : paths)
    names += (names.empty() ? "" : ", ") + std::filesystem::path(p).filename().string();
  auto reloaded = reload(paths);
  if (!reloaded) {
    log::error("reload", names + " changed; the new version was not started: " + reloaded.error() +
                             "\n  the running version carries on");
    return;
  }
  char took[32];
  std::snprintf(took, sizeof took, "%.1f ms", toSeconds(stats_.last) * 1000);
  log::info("reload", names + " changed: version " + std::to_string(stats_.reloads + 1) +
                          " took over in " + took);
}

}  // namespace pitwall
