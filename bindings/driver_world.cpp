#include "bindings/driver_world.hpp"

#include <time.h>

#include <cstdio>
#include <filesystem>

#include "bindings/world_copy.hpp"
#include "engine/core/log.hpp"

namespace pitwall {

namespace {

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

std::string fileName(const std::string& file) {
  return std::filesystem::path(file).filename().string();
}

// What runs inside the driver world's protected call: the director's values copied in (an
// allocation past the world's cap fails there, as a call, not as a panic), then
// pitwall._driverCall(method, …) (scripts/pitwall/driver_world.lua). Values, not one table of
// them: most calls carry no table at all (the car, its limit, the period), and then nothing is
// made in the world but the call.
struct CallIn {
  lua_State* from;
  int first, last;
  const char* method;
};

int callIn(lua_State* L) {
  const auto* in = static_cast<const CallIn*>(lua_touserdata(L, 1));
  lua_settop(L, 0);
  lua_getglobal(L, "pitwall");
  lua_getfield(L, -1, "_driverCall");
  lua_remove(L, -2);
  lua_pushstring(L, in->method);
  const int count = in->last - in->first + 1;
  luaL_checkstack(L, count + 8, "a driver call's values");
  std::vector<std::string> dropped;  // (quiet: what cannot cross is the director's own)
  lua::WorldCopy copy(in->from, L, dropped, true);
  // One memo for all the values (a table two of them share is one table in the world), made only
  // when there is a table to copy; it stands below the values, and goes when they are copied.
  bool tables = false;
  for (int i = in->first; i <= in->last && !tables; ++i)
    tables = lua_type(in->from, i) == LUA_TTABLE;
  if (tables) copy.openMemo();
  for (int i = in->first; i <= in->last; ++i)
    if (!copy.copy(i, "data", 0)) lua_pushnil(L);
  if (tables) copy.closeMemo();
  lua_call(L, 1 + count, 0);
  return 0;
}

// The same for the driver the file returned: pitwall._driverSetup(value, name).
int setupIn(lua_State* L) {
  lua_getglobal(L, "require");
  lua_pushliteral(L, "pitwall.driver_world");
  lua_call(L, 1, 1);
  lua_getfield(L, -1, "setup");
  lua_rotate(L, 1, 1);  // setup, value, name, module
  lua_pop(L, 1);
  lua_call(L, 2, 0);
  return 0;
}

}  // namespace

DriverWorld::DriverWorld(ScriptHost& race, AnkiCar& car, std::string file, DriverLimits limits)
    : race_(race), car_(car), file_(std::move(file)), name_(fileName(file_)), limits_(limits) {
  std::weak_ptr<bool> alive = alive_;
  // The run's world shuts down (the run ends): so does every driver world it made.
  race_.atShutDown([this, alive] {
    if (alive.expired()) return;
    watch_.reset();
    if (host_) host_->shutDown();
  });
  reload();
  if (limits_.watch) watch();
  // a desk's file (--code): its saves and the teacher's reset reach this world while it drives
  if (auto* room = race_.options().classroom;
      room && std::filesystem::path(file_).lexically_normal() ==
                  room->driverFile(car_.identity().number).lexically_normal()) {
    desk_ = room;
    room->attach(car_.identity().number, this);
  }
}

void DriverWorld::leaveDesk() {
  if (desk_) desk_->detach(car_.identity().number, this);
  desk_ = nullptr;
}

bool DriverWorld::restart(std::string& why) {
  if (closed_) {
    why = "the driver world is closed (its session ended)";
    return false;
  }
  if (reload()) return true;
  why = failure_.substr(0, failure_.find('\n'));
  return false;
}

DriverWorld::~DriverWorld() {
  leaveDesk();
  *alive_ = false;
  if (sweep_) race_.loop().cancel(sweep_);
}

void DriverWorld::retire() {
  if (host_) {
    host_->detach();
    host_->shutDown();
    retired_.push_back(std::move(host_));
  }
  if (!retired_.empty() && !sweep_) {
    std::weak_ptr<bool> alive = alive_;
    sweep_ = race_.loop().after(Duration::zero(), [this, alive] {
      if (alive.expired()) return;
      sweep_ = 0;
      retired_.clear();
    });
  }
}

void DriverWorld::close() {
  leaveDesk();
  closed_ = true;
  retire();
}

std::unique_ptr<ScriptHost> DriverWorld::open(std::string& why, const std::shared_ptr<bool>& live) {
  if (race_.isShutDown()) {
    why = "the run is ending";
    return nullptr;
  }
  HostOptions o;
  o.memory_limit = limits_.memory;
  o.budget = limits_.budget;
  o.seed = race_.options().seed;
  o.library_frames = race_.options().library_frames;
  o.driverCar = &car_;
  std::weak_ptr<bool> alive = alive_;
  auto loading = std::make_shared<std::string>();
  o.driverFailed = [this, alive, live, loading](const std::string& failure) {
    if (alive.expired()) return;
    if (*live)
      fail(failure);
    else if (loading->empty())
      *loading = failure;
  };
  std::unique_ptr<ScriptHost> host;
  try {
    host = std::make_unique<ScriptHost>(race_.loop(), race_.fleet(), nullptr, std::move(o));
  } catch (const std::exception& e) {
    why = std::string("its world did not open: ") + e.what();
    return nullptr;
  }
  // (its library failed: its memory cap, say)
  bool ok = loading->empty();
  if (ok) {
    if (auto loaded = host->loadFile(file_); !loaded) {
      *loading = "its file does not load: " + loaded.error();
      ok = false;
    }
  }
  if (ok) {
    lua_State* L = host->state();
    // The main chunk: what it returns is the driver (a class or an instance).
    ok = host->call(0, 1, "main chunk", name_);
    if (ok) {
      lua_pushcfunction(L, setupIn);
      lua_insert(L, -2);
      lua_pushstring(L, name_.c_str());
      ok = host->call(2, 0, "driver", name_);
    }
    ok = ok && loading->empty();
  }
  if (!ok) {
    why = loading->empty() ? "its driver did not set up" : *loading;
    host->detach();
    host->shutDown();
    retired_.push_back(std::move(host));  // (freed on a later turn, as a replaced world is)
    retire();
    return nullptr;
  }
  return host;
}

bool DriverWorld::reload() {
  if (closed_) return false;
  retire();
  failure_.clear();
  spent_.clear();
  spentSum_ = 0;
  ++version_;
  auto live = std::make_shared<bool>(false);
  std::string why;
  host_ = open(why, live);
  if (!host_) {
    if (!race_.isShutDown()) fail(why);
    return false;
  }
  *live = true;
  return failure_.empty();
}

bool DriverWorld::tryReload(std::string& why) {
  if (closed_) {
    why = "the driver world is closed (its session ended)";
    return false;
  }
  auto live = std::make_shared<bool>(false);
  auto made = open(why, live);
  if (!made) {
    why = why.substr(0, why.find('\n'));  // the sentence (the log keeps the traceback)
    return false;
  }
  retire();
  host_ = std::move(made);
  *live = true;
  failure_.clear();
  spent_.clear();
  spentSum_ = 0;
  ++version_;
  return true;
}

bool DriverWorld::call(lua_State* from, const char* method, int first) {
  if (!failure_.empty() || !host_ || host_->isShutDown()) return false;
  const int top = lua_gettop(from);
  CallIn in{from, lua_absindex(from, first), top, method};
  lua_State* L = host_->state();
  lua_pushcfunction(L, callIn);
  lua_pushlightuserdata(L, &in);
  const double cpu = threadCpuSeconds();
  // "update of driver alice.lua" of "car 2 (skull)"
  const std::string what = std::string(method) + " of driver " + name_;
  host_->call(1, 0, what.c_str(), car_.label());
  lua_settop(from, top);  // a copy cut short by an error leaves the director's stack as it was
  if (failure_.empty()) charge(threadCpuSeconds() - cpu);
  return failure_.empty();
}

void DriverWorld::fail(const std::string& why) {
  if (!failure_.empty()) return;
  failure_ = why.substr(0, why.find('\n'));  // the sentence; the log keeps the traceback
  (void)car_.stop();  // (a world that failed stopped it already: this one may never have run)
  if (host_ && !host_->isShutDown()) host_->shutDown();
  log::error("driver",
             "driver " + name_ + " of " + car_.label() + " is out, its car stopped: " + why);
}

void DriverWorld::charge(double cpu) {
  cpuTotal_ += cpu;
  // Real time only: in virtual time the CPU a call takes delays no one, and a race's result
  // must not depend on the machine.
  if (limits_.share <= 0 || limits_.shareCalls <= 0 || race_.loop().clockKind() != ClockKind::Real)
    return;
  spent_.push_back(cpu);
  spentSum_ += cpu;
  if (static_cast<int>(spent_.size()) > limits_.shareCalls) {
    spentSum_ -= spent_.front();
    spent_.pop_front();
  }
  const double budget = static_cast<double>(limits_.budget.count()) / 1000;
  const double average = spentSum_ / static_cast<double>(spent_.size());
  if (static_cast<int>(spent_.size()) < limits_.shareCalls || average <= limits_.share * budget)
    return;
  char text[300];
  std::snprintf(text, sizeof text,
                "its last %d calls took %.0f ms of CPU time on average, more than its share of "
                "the loop (%g %% of its budget of %.0f ms): a call may use the budget now and "
                "then, not every time (docs/drivers.md)",
                limits_.shareCalls, average * 1000, limits_.share * 100, budget * 1000);
  fail(text);
}

void DriverWorld::watch() {
  try {
    watch_ = std::make_unique<FileWatch>(race_.loop());
  } catch (const std::exception& e) {
    log::warn("driver", "cannot watch " + file_ + " for saves: " + e.what());
    return;
  }
  if (auto added = watch_->add(file_); !added) {
    log::warn("driver", "cannot watch " + file_ + " for saves: " + added.error());
    watch_.reset();
    return;
  }
  watch_->onChange = [this](const std::vector<std::string>&) {
    if (reload()) log::info("driver", "driver " + name_ + " of " + car_.label() + " reloaded");
  };
}

}  // namespace pitwall
