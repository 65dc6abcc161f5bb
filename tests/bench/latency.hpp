#pragma once
// Latency sampling shared by the end-to-end benchmarks (ble_bench.cpp, mqtt_bench.cpp): paths
// that take turns one sample at a time on one Loop, and their summary (nearest-rank percentiles).
#include <benchmark/benchmark.h>
#include <lua.hpp>

#include <algorithm>
#include <boost/asio/defer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/core/loop.hpp"

namespace pitwall::bench {

struct LatencyStats {
  double p50 = 0, p99 = 0, mean = 0, min = 0, max = 0;
};

inline LatencyStats summarize(std::vector<double> v) {
  LatencyStats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto rank = [&](double q) {  // nearest rank
    std::size_t k = static_cast<std::size_t>(q * static_cast<double>(v.size()) + 0.999999);
    return v[std::min(v.size(), std::max<std::size_t>(k, 1)) - 1];
  };
  s.p50 = rank(0.50);
  s.p99 = rank(0.99);
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  s.min = v.front();
  s.max = v.back();
  return s;
}

// The counters <name>50, <name>99, <name>Avg, <name>Min, <name>Max (µs).
inline void reportLatency(benchmark::State& state, const std::string& name, const LatencyStats& s) {
  state.counters[name + "50"] = s.p50;
  state.counters[name + "99"] = s.p99;
  state.counters[name + "Avg"] = s.mean;
  state.counters[name + "Min"] = s.min;
  state.counters[name + "Max"] = s.max;
}

// Takes turns among the paths, one sample in flight at a time. One sample: t0, the path's send()
// with a location id that differs from the previous one; its receiver calls arrived() with the
// location it got, which takes t1 and starts the next sample. The first `warmup` samples of each
// path are dropped.
struct Sampler {
  using Clock = std::chrono::steady_clock;

  struct Path {
    std::string name;
    std::function<void(std::uint8_t location)> send;
    std::vector<double> us;
  };
  // How long run() waits for an answer before it gives up: over the whole run, or (perSample)
  // for each sample.
  struct Watchdog {
    Duration limit;
    bool perSample = false;
  };

  Loop& loop;
  int warmup;
  Watchdog watch;
  std::vector<Path> paths;
  long next = 0, total = 0;
  std::size_t current = 0;
  int expected = -1;
  Clock::time_point t0;
  long strays = 0;  // arrivals that were not the sample in flight
  bool timedOut = false;
  Loop::TimerId watchdog = 0;

  Sampler(Loop& l, int warmupSamples, Watchdog w) : loop(l), warmup(warmupSamples), watch(w) {}

  void add(std::string name, std::function<void(std::uint8_t)> send) {
    paths.push_back({std::move(name), std::move(send), {}});
  }

  // Every receiver calls this with the location id it got.
  void arrived(long location) {
    auto t1 = Clock::now();
    if (location != expected) {
      ++strays;
      return;
    }
    expected = -1;
    if (next > static_cast<long>(paths.size()) * warmup)
      paths[current].us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    if (next == total) return loop.stop();
    // defer, not Loop::post: a continuation goes to this thread's private queue, where a post
    // from inside a handler would interrupt the reactor (an epoll_ctl and one more epoll_wait)
    // and put that harness cost on whichever sample comes next.
    boost::asio::defer(loop.io(), [this] { fire(); });
  }

  void fire() {
    if (watch.perSample) armWatchdog();
    current = static_cast<std::size_t>(next % static_cast<long>(paths.size()));
    auto location = static_cast<std::uint8_t>(next & 0xff);
    ++next;
    expected = location;
    t0 = Clock::now();
    paths[current].send(location);
  }

  // Runs warmup + samples per path; false when a sample got lost (no answer in time).
  bool run(int samples) {
    total = static_cast<long>(paths.size()) * (warmup + samples);
    if (!watch.perSample) armWatchdog();
    loop.post([this] { fire(); });
    loop.run();
    if (watchdog) loop.cancel(watchdog);
    watchdog = 0;
    return !timedOut;
  }

  // The counters of every path (reportLatency) and `strays`; returns the path's summaries in
  // the order they were added.
  std::vector<LatencyStats> report(benchmark::State& state) const {
    std::vector<LatencyStats> all;
    for (const auto& p : paths) {
      all.push_back(summarize(p.us));
      reportLatency(state, p.name, all.back());
    }
    state.counters["strays"] = static_cast<double>(strays);
    return all;
  }

 private:
  void armWatchdog() {
    if (watchdog) loop.cancel(watchdog);
    watchdog = loop.after(watch.limit, [this] {
      watchdog = 0;
      timedOut = true;
      loop.stop();
    });
  }
};

inline int luaMark(lua_State* L) {
  auto* sampler = static_cast<Sampler*>(lua_touserdata(L, lua_upvalueindex(1)));
  sampler->arrived(static_cast<long>(luaL_checkinteger(L, 1)));
  return 0;
}

// The receiver at the end of an engine path: a global mark(location) in `host`'s Lua that
// calls sampler.arrived(), and the first car's onPosition handler calling mark(ev.location).
// The error when the script did not start.
inline std::string startMarking(ScriptHost& host, Sampler& sampler, const std::string& chunk) {
  lua_State* L = host.state();
  lua_pushlightuserdata(L, &sampler);
  lua_pushcclosure(L, luaMark, 1);
  lua_setglobal(L, "mark");
  auto started = host.startString(
      "pitwall.cars()[1].onPosition = function(car, ev) mark(ev.location) end", chunk);
  return started ? std::string() : started.error();
}

}  // namespace pitwall::bench
