// pitwall try FILE: a driver file alone in the simulator, in virtual time, under the real sensor
// model — its laps, its best, its speed along the lap — in a second or two (docs/cli.md): what a
// student runs before a league, and what the view's code editor's "Test" will run off the race's
// loop (issue 39). One heat of the league's (engine/cli/league_heat), with a trace.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/cli/fail.hpp"
#include "engine/cli/league_heat.hpp"
#include "engine/cli/options.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::cli {

namespace {

namespace fs = std::filesystem;

struct TryOptions {
  std::string file;
  int laps = 3;
  std::string track = "oval";
  std::string sensor = "real";
  std::uint64_t seed = 1;
  bool json = false;
  DriverLimitOptions limits;
};

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f s", s);
  return text;
}

// The best lap's speed along the lap: the trace's samples of that lap, every `step` mm (the
// fastest sample in each stretch), as "0 m 820 · 0.5 m 900 · …".
std::string speedAlong(const nlohmann::json& trace, int lap, double step) {
  std::string out;
  double next = 0, fastest = -1;
  for (const auto& s : trace) {
    if (s.value("lap", -1) != lap) continue;
    const double d = s.value("distance", 0.0), v = s.value("speed", 0.0);
    fastest = std::max(fastest, v);
    if (d >= next) {
      char text[48];
      std::snprintf(text, sizeof text, "%s%.1f m %.0f", out.empty() ? "" : " · ", next / 1000,
                    fastest);
      out += text;
      fastest = -1;
      next += step;
    }
  }
  return out;
}

int tryDriver(const TryOptions& o) {
  std::error_code ec;
  if (!fs::is_regular_file(o.file, ec))
    return fail("try", o.file + ": no such file (give a driver file, such as alice.lua)", 2);
  // a usage error as for `league`: said before anything runs
  if (auto track = sim::loadLayout(o.track); !track) return fail("try", track.error());
  HeatSpec spec;
  spec.files = {fs::absolute(o.file, ec).lexically_normal().string()};
  spec.qualifying = true;  // alone, its laps counted, its best kept
  spec.laps = o.laps;
  spec.track = o.track;
  spec.sensor = o.sensor;
  spec.seed = o.seed;
  spec.title = "Try";
  spec.limits.memory = static_cast<std::size_t>(o.limits.driverMemory) << 20;
  spec.limits.budget = std::chrono::milliseconds(std::llround(o.limits.driverBudget * 1000));
  spec.trace = true;
  ScenarioResult r = runHeat(spec);
  if (!r.passed()) return fail("try", r.message, 1);
  const nlohmann::json data = nlohmann::json::parse(r.data, nullptr, false);
  if (!data.is_object() || !data.contains("rows") || data["rows"].empty())
    return fail("try", "the run gave no result", 1);
  const nlohmann::json& row = data["rows"][0];
  const nlohmann::json& trace = data["trace"];
  const std::string name = fs::path(o.file).filename().string();
  // not finished: out (a failure, its reason), or still on its way when the heat's cap came
  const bool out = row.value("status", "") != "finished";
  const std::string why = row.contains("reason") && row["reason"].is_string()
                              ? row["reason"].get<std::string>()
                              : "it did not finish its laps (" + row.value("status", "?") + ")";
  std::vector<double> laps;
  for (const auto& t : row["lapTimes"])
    if (t.is_number()) laps.push_back(t.get<double>());
  int best = 0;
  for (std::size_t k = 1; k < laps.size(); ++k)
    if (laps[k] < laps[static_cast<std::size_t>(best)]) best = static_cast<int>(k);
  if (o.json) {
    nlohmann::json j = {{"file", name},
                        {"track", o.track},
                        {"sensor", o.sensor},
                        {"laps", laps},
                        {"status", row.value("status", "")},
                        {"simulated", r.simulated}};
    j["best"] = laps.empty() ? nlohmann::json(nullptr) : nlohmann::json(laps[best]);
    j["bestLap"] = laps.empty() ? nlohmann::json(nullptr) : nlohmann::json(best + 1);
    j["reason"] = row.contains("reason") ? row["reason"] : nlohmann::json(nullptr);
    nlohmann::json samples = nlohmann::json::array();
    for (const auto& s : trace)
      samples.push_back({{"time", s["time"]},
                         {"lap", s["lap"]},
                         {"distance", s["distance"]},
                         {"speed", s["speed"]}});
    j["trace"] = samples;
    std::cout << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return out ? 1 : 0;
  }
  std::cout << name << " alone on " << o.track << " (" << o.sensor << " sensors), "
            << seconds(r.simulated) << " simulated\n";
  for (std::size_t k = 0; k < laps.size(); ++k)
    std::cout << "  lap " << k + 1 << "  " << seconds(laps[k])
              << (static_cast<int>(k) == best ? "  best" : "") << "\n";
  if (!laps.empty()) {
    // a lap's number in the trace: laps counted at its start (the first lap is 1 after the line)
    std::cout << "  speed along lap " << best + 1 << " (mm/s): " << speedAlong(trace, best + 1, 500)
              << "\n";
  }
  if (out) {
    std::cout << "  out after " << laps.size() << (laps.size() == 1 ? " lap: " : " laps: ") << why
              << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

Command addTryCommand(CLI::App& app) {
  auto o = std::make_shared<TryOptions>();
  auto* cmd = app.add_subcommand(
      "try",
      "A driver file alone in the simulator, in virtual time: its laps, its best, its speed "
      "along the lap (docs/cli.md)");
  cmd->add_option("file", o->file, "The driver file (as for pitwall league or --driver)")
      ->required();
  cmd->add_option("--laps", o->laps, "Laps to drive (default 3)")->check(CLI::Range(1, 20));
  cmd->add_option("--track", o->track, "The layout: a name (oval, …) or a layout file");
  cmd->add_option("--sensor", o->sensor,
                  "The simulated car's sensors: real (default, as real cars report) or ideal")
      ->check(CLI::IsMember({"real", "ideal"}));
  cmd->add_option("--seed", o->seed, "The simulator's seed (default 1)");
  cmd->add_flag("--json", o->json,
                "One JSON object: laps, best, status, reason, and the speed trace (time, lap, "
                "distance, speed every 0.05 s)");
  addDriverLimits(cmd, o->limits, "the driver world");
  return {cmd, [o] { return tryDriver(*o); }};
}

}  // namespace pitwall::cli
