// Hot reload (docs/hot-reload.md): how long from "the script changed" to "the new handlers are
// active", for a small and a 2000-line script, and how many car events per second the engine
// still delivers to Lua while the script is reloaded ten times a second.
//
// BM_Reload/…:        Reloader::reload() alone: compile, onUnload, persist copy, trial start,
//                     swap, close the old world. Four cars, each with handlers.
// BM_SaveToActive/…:  the whole way as a user sees it: the file is rewritten on disk, inotify
//                     tells the loop, the debounce passes, the new version takes over (real
//                     clock). The argument is the debounce in ms (100 is pitwall's).
// BM_Events…:         position frames through AnkiCar::receive into a Lua onPosition handler,
//                     without reloads and with a reload every 100 ms of wall time.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "bindings/reloader.hpp"
#include "engine/core/log.hpp"
#include "tests/bench/frames.hpp"

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
         "  car.onPosition = function(c, ev) p.events = p.events + 1 end\n"
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

void BM_SaveToActive(benchmark::State& state) {
  auto debounce = std::chrono::milliseconds(state.range(0));
  bool large = state.range(1) != 0;
  Rig rig(ClockKind::Real);
  rig.write(large ? largeScript(0) : smallScript(0));
  if (!rig.scripts->start(rig.file.string())) return state.SkipWithError("the script failed");
  if (!rig.scripts->watch(debounce)) return state.SkipWithError("cannot watch");
  rig.scripts->onNewVersion = [&](ScriptHost&) { rig.loop.stop(); };
  // Two versions made beforehand, saved in turn: the clock covers the save and what follows.
  std::string versions[2] = {large ? largeScript(1) : smallScript(1),
                             large ? largeScript(2) : smallScript(2)};
  int version = 1;
  for (auto _ : state) {
    rig.write(versions[version % 2]);  // what an editor does
    auto give_up = rig.loop.after(std::chrono::seconds(5), [&] { rig.loop.stop(); });
    rig.loop.run();
    rig.loop.cancel(give_up);
    if (rig.scripts->stats().reloads != version)
      return state.SkipWithError("the save did not reload the script");
    ++version;
  }
  state.SetLabel(std::string(large ? "large" : "small") + " script, debounce " +
                 std::to_string(debounce.count()) + " ms");
}
BENCHMARK(BM_SaveToActive)
    ->Args({100, 0})
    ->Args({100, 1})
    ->Args({5, 0})
    ->Args({5, 1})
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond);

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
