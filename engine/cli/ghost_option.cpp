#include "engine/cli/ghost_option.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "engine/core/printable.hpp"
#include "engine/laps/trace_json.hpp"

namespace pitwall::cli {

Result<std::optional<KeptBest>, std::string> keptBest(standings::Database& db,
                                                      const sim::Track& track,
                                                      const std::string& who) {
  auto kept = db.bestLaps(sim::layoutText(track), who);
  if (!kept) return Unexpected{kept.error()};
  // The fastest that is a lap a ghost can drive: one damaged or edited by hand is passed over
  // (and said, when none is left)
  std::optional<std::string> problem;
  const double lapLength = laps::LapMap(track).lap;
  for (const standings::KeptLap& k : *kept) {
    const std::string label = printable(k.driver, 80) + "'s personal best in " +
                              printable(k.car, 80) + " (" + printable(k.when, 40) + ")";
    auto trace = laps::traceFromJson(nlohmann::json::parse(k.trace, nullptr, false));
    std::string why;
    if (!trace)
      why = trace.error();
    else if (std::abs(trace->time - k.lap) > 1e-3)
      why = "its trace's time is not its lap's";
    else if (std::abs(trace->length - lapLength) > 1)
      why = "a lap of another length than this track's";
    else if (trace->time * sim::GhostLap::kMaxSpeed < trace->length)
      why = "faster than any car";
    if (why.empty()) return std::optional<KeptBest>(KeptBest{std::move(*trace), label});
    if (!problem)
      problem = db.path() + " keeps " + label + " damaged (" + why +
                "), and no other personal best here a ghost can drive: race the track again, "
                "which keeps a new one, or give a record: --ghost FILE[:CAR[:LAP]]";
  }
  if (problem) return Unexpected{*problem};
  return std::optional<KeptBest>();
}

namespace {

Result<view::Ghost, std::string> personalBest(const std::string& who, const sim::Track& track,
                                              standings::Database* db) {
  if (!db)
    return Unexpected{std::string(
        "--ghost best races a personal best the standings keep, and this run keeps none "
        "(--no-db, or no database could be opened: the run said why): give --db FILE, or a "
        "record: --ghost FILE[:CAR[:LAP]]")};
  auto kept = keptBest(*db, track, who);
  if (!kept) return Unexpected{kept.error()};
  if (!*kept)
    return Unexpected{db->path() + " keeps no personal best" +
                      (who.empty() ? "" : " of " + printable(who, 80)) + " on this track (" +
                      printable(sim::layoutText(track), 80) +
                      "): race it once with the standings on, or give a record: --ghost "
                      "FILE[:CAR[:LAP]]"};
  return view::ghostOf((*kept)->lap, (*kept)->label, track, {});
}

}  // namespace

Result<view::Ghost, std::string> resolveGhost(const std::string& spec, const sim::Track& track,
                                              standings::Database* db) {
  if (spec == "best") return personalBest("", track, db);
  if (spec.rfind("best:", 0) == 0) return personalBest(spec.substr(5), track, db);
  auto split = view::splitLapSpec(spec);
  if (!split) return Unexpected{"--ghost " + split.error()};
  auto ghost = view::ghostSpec(split->first, split->second, track, {}, kMaxGhostRecordBytes);
  if (!ghost) return Unexpected{"--ghost: " + ghost.error()};
  return ghost;
}

}  // namespace pitwall::cli
