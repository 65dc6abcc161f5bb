// Hot reload (docs/hot-reload.md): how long from "the script changed" to "the new handlers are
// active", for a small and a 2000-line script, and how many car events per second the engine
// still delivers to Lua while the script is reloaded ten times a second.
//
// BM_Reload/…:        Reloader::reload() alone: compile, onUnload, persist copy, trial start,
//                     swap, close the old world. Four cars, each with handlers.
// BM_SaveToNewHandlers/…: the whole way as a user sees it (issue 14: ≤ 20 ms): the script file
//                     is written and closed while car events flow (a position frame every
//                     0.25 ms), inotify tells the loop, the new version takes over, and the clock
//                     stops at the first event handled by a handler of the new version (real
//                     clock, manual time). Each save comes after the burst window of the one
//                     before has closed, as a user's saves do. The first argument is the burst
//                     window in ms (100 is pitwall's); every event sent must reach Lua once.
// BM_SaveToInotifyFloor: the floor of that path: a file written and closed → an inotify watch
//                     on its folder wakes the same loop and reads the event. No Lua.
// BM_Events…:         position frames through AnkiCar::receive into a Lua onPosition handler,
//                     without reloads and with a reload every 100 ms of wall time.
#include <benchmark/benchmark.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "bindings/reloader.hpp"
#include "engine/core/log.hpp"
#include "engine/sim/grid.hpp"
#include "tests/bench/frames.hpp"
#include "tests/support/run_until.hpp"
#include "tests/support/sim_cars.hpp"

namespace {

using namespace pitwall;
namespace fs = std::filesystem;

// A script as a user writes one: handlers on every car, a timer, state in pitwall.persist.
std::string smallScript(int version) {
  return "-- version " + std::to_string(version) +
         "\n"
         "local p = pitwall.persist\n"
         "p.events = p.events or 0\n"
         "p.laps = p.laps or {}\n"
         "for _, car in ipairs(pitwall.cars()) do\n"
         "  car.onPosition = function(c, ev)\n"
         "    p.events = p.events + 1\n"
         "    if mark then mark() end\n"
         "  end\n"
         "  car.onTransition = function(c, ev) p.last = ev.piece end\n"
         "end\n"
         "pitwall.every(0.5, function() p.tick = pitwall.now() end)\n";
}

int lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

// 2000 lines: the small script and what a strategy grows, tables of numbers and small functions
// over them.
std::string largeScript(int version) {
  std::string s = smallScript(version);
  s += "local strategy = {}\n";
  for (int i = 0; lines(s) + 6 <= 2000; ++i) {
    std::string n = std::to_string(i);
    s += "strategy.table" + n + " = {" + n + ", " + n + " * 2, " + n + " * 3, name = 'row" + n +
         "'}\n";
    s += "function strategy.f" + n + "(car, ev)\n";
    s += "  local speed = (ev and ev.speed or 0) + " + n + "\n";
    s += "  if speed > 1000 then return 1000 end\n";
    s += "  return speed\n";
    s += "end\n";
  }
  return s;
}

struct Rig {
  Loop loop;
  Fleet fleet{loop};
  std::vector<AnkiCar*> cars;
  std::unique_ptr<Reloader> scripts;
  fs::path dir;
  fs::path file;

  explicit Rig(ClockKind clock = ClockKind::Virtual) : loop(clock) {
    log::setLevel(log::Level::Error);
    dir = fs::temp_directory_path() / ("pitwall-reload-bench-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    file = dir / "strategy.lua";
    for (int i = 0; i < 4; ++i) {
      cars.push_back(&fleet.add(std::make_unique<bench::BenchLink>(), CarIdentity{}));
    }
    scripts = std::make_unique<Reloader>(loop, fleet, nullptr, HostOptions{});
  }
  ~Rig() {
    scripts.reset();
    fs::remove_all(dir);
  }
  void write(const std::string& code) {
    std::ofstream out(file);
    out << code;
  }
  double events() {
    lua_State* L = scripts->host().state();
    luaL_dostring(L, "return pitwall.persist.events");
    double v = lua_tonumber(L, -1);
    lua_pop(L, 1);
    return v;
  }
};

void BM_Reload(benchmark::State& state) {
  bool large = state.range(0) != 0;
  Rig rig;
  std::string code = large ? largeScript(1) : smallScript(1);
  rig.write(code);
  if (!rig.scripts->start(rig.file.string())) return state.SkipWithError("the script failed");
  for (auto _ : state) {
    auto reloaded = rig.scripts->reload();
    if (!reloaded) return state.SkipWithError(reloaded.error().c_str());
  }
  state.counters["lines"] = lines(code);
  state.SetLabel(large ? "large script" : "small script");
}
BENCHMARK(BM_Reload)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A race under way, reloaded: the grand prix's shape (4 simulated cars, 4 drivers, race.laps
// with the leaderboard's bookkeeping) saved mid-race. Each reload carries the session into a
// new Lua world (pitwall._carry, copyCarried), whose race.laps takes it up (maps, trackers, lap
// timers, drivers' takeover) — the engine's part of a save of examples/grand_prix.lua.
void BM_ReloadRace(benchmark::State& state) {
  log::setLevel(log::Level::Error);
  Loop loop(ClockKind::Virtual);
  SimSession sim;
  sim.world = std::make_unique<sim::World>(loop, *sim::loadLayout("oval"), 1);
  Fleet fleet(loop);
  for (int i = 0; i < 4; ++i)
    testing::addSimulatedCar(loop, fleet, *sim.world, sim::gridSpec(sim.world->track(), i));
  auto runFor = [&](Duration d) {
    auto id = loop.after(d, [&] { loop.stop(); });
    loop.run();
    loop.cancel(id);
  };
  runFor(std::chrono::seconds(1));
  fs::path dir = fs::temp_directory_path() / ("pitwall-race-bench-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path file = dir / "grand_prix.lua";
  std::ofstream(file) << "local race = require 'pitwall.race'\n"
                         "local lineup = {'cruiser', 'lanekeeper', 'follower', 'overtaker'}\n"
                         "race.laps { laps = 1000, results = false,\n"
                         "  drivers = function(car, i) return lineup[i] end }\n";
  Reloader scripts(loop, fleet, &sim, HostOptions{});
  if (!scripts.start(file.string())) return state.SkipWithError("the race did not start");
  runFor(std::chrono::seconds(40));  // lights, then laps: mid-race
  for (auto _ : state) {
    auto reloaded = scripts.reload();
    if (!reloaded) return state.SkipWithError(reloaded.error().c_str());
  }
  runFor(std::chrono::seconds(5));  // and it races on: every car driving, none ever stopped
  for (const auto& car : sim.world->cars()) {
    auto t = car->truth();
    if (t.speed_mm_s <= 0 || t.stop_commands > 0)
      return state.SkipWithError("a car stopped: the race did not survive the reloads");
  }
  state.counters["reloads"] = scripts.stats().reloads;
  fs::remove_all(dir);
}
BENCHMARK(BM_ReloadRace)->Unit(benchmark::kMillisecond);

// mark(), set as a global in each new version: the first event its handlers take stops the clock
// (and the loop). The old version has no mark.
struct FirstEvent {
  Loop* loop = nullptr;
  bool seen = false;
  std::chrono::steady_clock::time_point swapped, handled;
};

int markFirstEvent(lua_State* L) {
  auto* first = static_cast<FirstEvent*>(lua_touserdata(L, lua_upvalueindex(1)));
  if (!first->seen) {
    first->seen = true;
    first->handled = std::chrono::steady_clock::now();
    first->loop->stop();
  }
  lua_pushnil(L);
  lua_setglobal(L, "mark");
  return 0;
}

void BM_SaveToNewHandlers(benchmark::State& state) {
  auto window = std::chrono::milliseconds(state.range(0));
  bool large = state.range(1) != 0;
  Rig rig(ClockKind::Real);
  rig.write(large ? largeScript(0) : smallScript(0));
  if (!rig.scripts->start(rig.file.string())) return state.SkipWithError("the script failed");
  if (!rig.scripts->watch(window)) return state.SkipWithError("cannot watch");
  FirstEvent first;
  first.loop = &rig.loop;
  rig.scripts->onNewVersion = [&](ScriptHost& host) {
    first.swapped = std::chrono::steady_clock::now();
    lua_State* L = host.state();
    lua_pushlightuserdata(L, &first);
    lua_pushcclosure(L, markFirstEvent, 1);
    lua_setglobal(L, "mark");
  };
  // The cars' position frames, one every 0.25 ms, round robin, while the loop runs.
  anki::Frame frame = bench::positionFrame();
  std::uint8_t location = 0;
  long sent = 0;
  std::function<void()> feed = [&] {
    frame.bytes[bench::kLocationByte] = ++location;
    rig.cars[sent & 3]->receive(frame.span());
    ++sent;
    rig.loop.after(std::chrono::microseconds(250), feed);
  };
  rig.loop.post(feed);
  testing::runFor(rig.loop, window);
  // Two versions made beforehand, saved in turn: the clock covers the save and what follows.
  std::string versions[2] = {large ? largeScript(1) : smallScript(1),
                             large ? largeScript(2) : smallScript(2)};
  int version = 1;
  double writeMs = 0, swapMs = 0, reloadMs = 0;
  for (auto _ : state) {
    first.seen = false;
    auto saved = std::chrono::steady_clock::now();
    rig.write(versions[version % 2]);  // what an editor does: written and closed
    writeMs +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - saved).count();
    auto give_up = rig.loop.after(std::chrono::seconds(5), [&] { rig.loop.stop(); });
    rig.loop.run();
    rig.loop.cancel(give_up);
    if (!first.seen || rig.scripts->stats().reloads != version)
      return state.SkipWithError("the save did not reach the new version's handlers");
    state.SetIterationTime(std::chrono::duration<double>(first.handled - saved).count());
    swapMs += std::chrono::duration<double, std::milli>(first.swapped - saved).count();
    reloadMs += toSeconds(rig.scripts->stats().last) * 1000;
    ++version;
    // The next save is a new burst: the window of this one closes first, events flowing.
    testing::runFor(rig.loop, window + std::chrono::milliseconds(20));
  }
  if (rig.events() != static_cast<double>(sent))
    return state.SkipWithError("events were lost or duplicated across the reloads");
  int n = version - 1;
  state.counters["write_ms"] = writeMs / n;    // of which the write and close themselves
  state.counters["swap_ms"] = swapMs / n;      // save → the new version took over
  state.counters["reload_ms"] = reloadMs / n;  // of which Reloader::reload() itself
  state.counters["events"] = static_cast<double>(sent);
  state.counters["lost"] = 0;
  state.SetLabel(std::string(large ? "large" : "small") + " script, window " +
                 std::to_string(window.count()) + " ms");
}
BENCHMARK(BM_SaveToNewHandlers)
    ->Args({100, 0})
    ->Args({100, 1})
    ->Iterations(30)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The floor: write and close a file, and an inotify watch on its folder wakes the same kind of
// loop, which reads the event.
void BM_SaveToInotifyFloor(benchmark::State& state) {
  Loop loop(ClockKind::Real);
  fs::path dir =
      fs::temp_directory_path() / ("pitwall-inotify-bench-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path file = dir / "strategy.lua";
  int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  ::inotify_add_watch(fd, dir.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO);
  boost::asio::posix::stream_descriptor watch(loop.io(), fd);
  std::string code = smallScript(1);
  std::chrono::steady_clock::time_point woke;
  std::function<void()> wait = [&] {
    watch.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                     [&](const boost::system::error_code& ec) {
                       if (ec) return;
                       alignas(inotify_event) char buf[4096];
                       bool closed = false;
                       for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) closed = true;
                       if (closed) {
                         woke = std::chrono::steady_clock::now();
                         loop.stop();
                       }
                       wait();
                     });
  };
  wait();
  double writeMs = 0;
  for (auto _ : state) {
    auto saved = std::chrono::steady_clock::now();
    std::ofstream(file) << code;
    writeMs +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - saved).count();
    auto give_up = loop.after(std::chrono::seconds(5), [&] { loop.stop(); });
    loop.run();
    loop.cancel(give_up);
    state.SetIterationTime(std::chrono::duration<double>(woke - saved).count());
  }
  state.counters["write_ms"] = writeMs / static_cast<double>(state.iterations());
  watch.close();
  fs::remove_all(dir);
}
BENCHMARK(BM_SaveToInotifyFloor)->Iterations(30)->UseManualTime()->Unit(benchmark::kMillisecond);

// Events into Lua, reloading every `period` of wall time (0: never).
void events(benchmark::State& state, std::chrono::milliseconds period) {
  Rig rig;
  rig.write(smallScript(1));
  if (!rig.scripts->start(rig.file.string())) return state.SkipWithError("the script failed");
  anki::Frame frame = bench::positionFrame();
  std::uint8_t location = 0;
  long sent = 0;
  auto lastReload = std::chrono::steady_clock::now();
  for (auto _ : state) {
    for (int i = 0; i < 1000; ++i) {
      frame.bytes[bench::kLocationByte] = ++location;
      rig.cars[i & 3]->receive(frame.span());
    }
    sent += 1000;
    if (period.count() > 0 && std::chrono::steady_clock::now() - lastReload >= period) {
      if (!rig.scripts->reload()) return state.SkipWithError("reload failed");
      lastReload = std::chrono::steady_clock::now();
    }
  }
  if (rig.events() != static_cast<double>(sent))
    return state.SkipWithError("events were lost or duplicated across the reloads");
  state.SetItemsProcessed(sent);
  state.counters["reloads"] = rig.scripts->stats().reloads;
}

void BM_EventsWithoutReloads(benchmark::State& state) {
  events(state, std::chrono::milliseconds(0));
}
BENCHMARK(BM_EventsWithoutReloads)->MinTime(2.0);

void BM_EventsReloading10PerSecond(benchmark::State& state) {
  events(state, std::chrono::milliseconds(100));
}
BENCHMARK(BM_EventsReloading10PerSecond)->MinTime(2.0);

}  // namespace
