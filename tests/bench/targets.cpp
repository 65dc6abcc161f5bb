#include "tests/bench/targets.hpp"

#include <cstdio>
#include <functional>
#include <optional>

namespace pitwall::bench {

void TargetReporter::ReportRuns(const std::vector<Run>& runs) {
  ConsoleReporter::ReportRuns(runs);
  for (const Run& run : runs) {
    if (run.error_occurred) continue;
    // Repetitions: keep the median; a single run: keep it.
    if (run.run_type == Run::RT_Aggregate && run.aggregate_name != "median") continue;
    Figures f;
    f.realSeconds = run.GetAdjustedRealTime() /
                    benchmark::GetTimeUnitMultiplier(run.time_unit);  // unit → seconds
    for (const auto& [name, counter] : run.counters) f.counters[name] = counter.value;
    runs_[run.run_name.str()] = std::move(f);
  }
}

const TargetReporter::Figures* TargetReporter::find(const std::string& name) const {
  auto it = runs_.find(name);
  return it == runs_.end() ? nullptr : &it->second;
}

namespace {

struct Target {
  const char* what;
  const char* unit;  // how the figure is shown: "x", "%", "MB", "k/s", "ms", "s"
  bool atMost;       // true: figure ≤ bound; false: figure ≥ bound
  double bound;
};

std::string show(double v, const char* unit) {
  char buf[64];
  std::string u = unit;
  if (u == "x")
    std::snprintf(buf, sizeof buf, "%.2f×", v);
  else if (u == "%")
    std::snprintf(buf, sizeof buf, "%.1f %%", 100 * v);
  else if (u == "k/s")
    std::snprintf(buf, sizeof buf, "%.1f k/s", v / 1000);
  else
    std::snprintf(buf, sizeof buf, "%.2f %s", v, unit);
  return buf;
}

// `text` padded with spaces to `width` characters (UTF-8: ×, ≤, → are one character each).
std::string pad(const std::string& text, std::size_t width, bool right = false) {
  std::size_t chars = 0;
  for (unsigned char c : text) chars += (c & 0xC0) != 0x80 ? 1 : 0;
  std::string fill(chars < width ? width - chars : 0, ' ');
  return right ? fill + text : text + fill;
}

}  // namespace

void TargetReporter::printTargets() const {
  auto counter = [this](const char* run, const char* name) -> std::optional<double> {
    const Figures* f = find(run);
    if (!f) return std::nullopt;
    auto it = f->counters.find(name);
    if (it == f->counters.end()) return std::nullopt;
    return it->second;
  };
  auto ratioOf = [&](std::optional<double> a, std::optional<double> b) -> std::optional<double> {
    if (!a || !b || *b == 0) return std::nullopt;
    return *a / *b;
  };
  auto wall = [this](const char* run) -> std::optional<double> {
    const Figures* f = find(run);
    if (!f) return std::nullopt;
    return f->realSeconds;
  };

  struct Row {
    Target target;
    std::optional<double> figure;
    const char* from;
  };
  std::vector<Row> rows{
      {{"frame → Lua, typical (÷ Lua floor)", "x", true, 1.10},
       counter("BM_FrameToLuaRatio", "ratio"),
       "BM_FrameToLuaRatio"},
      {{"frame → Lua, every field changing (÷ floor)", "x", true, 1.25},
       counter("BM_FrameToLuaRatio", "every_ratio"),
       "BM_FrameToLuaRatio"},
      {{"frame → Lua with --view, nobody watching (÷ no view)", "x", true, 1.20},
       counter("BM_FrameToLuaViewRatio/min_time:2.000", "ratio"),
       "BM_FrameToLuaViewRatio"},
      {{"--fast: system time of the CPU time", "%", true, 0.10},
       counter("BM_CliFast/iterations:5/manual_time", "sys_share"),
       "BM_CliFast"},
      {{"--fast: in-process ÷ CLI sim-s per CPU-s", "x", true, 1.30},
       counter("BM_CliFast/iterations:5/manual_time", "in_process_ratio"),
       "BM_CliFast"},
      {{"1000 cars in real time: share of one core", "%", true, 0.50},
       counter("BM_CliRealTime/1000/iterations:1/manual_time", "cpu_share"),
       "BM_CliRealTime"},
      {{"memory, 8 cars", "MB", true, 20},
       counter("BM_CliMemory/8/iterations:1/manual_time", "peak_mb"),
       "BM_CliMemory/8"},
      {{"memory, 1000 cars", "MB", true, 64},
       counter("BM_CliMemory/1000/iterations:1/manual_time", "peak_mb"),
       "BM_CliMemory/1000"},
      {{"MQTT: vehicle messages/s through the broker", "k/s", false, 50000},
       counter("BM_MqttBridgeThroughput/cars:4/window:64/broker_nodelay:1/iterations:1/manual_time",
               "msg_per_s"),
       "BM_MqttBridgeThroughput/cars:4/window:64/broker_nodelay:1"},
      {{"MQTT: frame on A → Lua on B, p99", "ms", true, 1.0},
       [&]() -> std::optional<double> {
         auto us = counter(
             "BM_MqttFrameToLua/samples:2000/broker_nodelay:1/iterations:1/manual_time", "eng99");
         if (!us) return std::nullopt;
         return *us / 1000;
       }(),
       "BM_MqttFrameToLua/samples:2000/broker_nodelay:1"},
      {{"league: CPU a four-car, five-lap race (driver worlds)", "ms", true, 20},
       counter("BM_League/1/iterations:1/manual_time", "cpu_ms_per_race"),
       "BM_League/1"},
      {{"league: 1000 races with -j 2, wall", "s", true, 10},
       counter("BM_League/2/iterations:1/manual_time", "wall_s_per_1000"),
       "BM_League/2"},
      {{"scenario tests (tests/scenarios -j 2), wall", "s", true, 1.0},
       wall("BM_ScenarioSuite/iterations:3/manual_time"),
       "BM_ScenarioSuite"},
  };

  std::printf("\nTargets (issues 20, 35 and 38; docs/performance.md):\n");
  std::printf("  %s %s %s  met\n", pad("", 46).c_str(), pad("measured", 12, true).c_str(),
              pad("target", 12, true).c_str());
  int met = 0, measured = 0;
  for (const Row& r : rows) {
    std::string target =
        std::string(r.target.atMost ? "≤ " : "≥ ") + show(r.target.bound, r.target.unit);
    std::string figure = r.figure ? show(*r.figure, r.target.unit) : "-";
    bool ok =
        r.figure && (r.target.atMost ? *r.figure <= r.target.bound : *r.figure >= r.target.bound);
    measured += r.figure ? 1 : 0;
    met += ok ? 1 : 0;
    std::printf("  %s %s %s  %s\n", pad(r.target.what, 46).c_str(), pad(figure, 12, true).c_str(),
                pad(target, 12, true).c_str(),
                !r.figure ? ("not run (" + std::string(r.from) + ")").c_str()
                : ok      ? "yes"
                          : "NO");
  }
  std::printf("  %d of %d measured targets met (%zu targets)\n", met, measured, rows.size());
  // Why the every-field target is out of reach (docs/performance.md "Frame → Lua: the plumbing
  // cut, and the floor"):
  // the bare C API doing only what that event must deliver is already above it.
  auto own = counter("BM_FrameToLuaRatio", "every_own_ratio");
  auto floorOfWork = ratioOf(counter("BM_FrameToLuaRatio", "every_floor_ns"),
                             counter("BM_FrameToLuaRatio", "floor_ns"));
  if (own && floorOfWork)
    std::printf(
        "  every field changing: %.2f× a floor doing the same Lua work by hand, a floor that is "
        "itself %.2f× the 3-field floor\n",
        *own, *floorOfWork);
}

}  // namespace pitwall::bench
