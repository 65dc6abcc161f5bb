#include "engine/cli/ghost_option.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "engine/core/printable.hpp"
#include "engine/laps/trace_json.hpp"

namespace pitwall::cli {

Result<std::optional<KeptBest>, std::string> keptBest(standings::Database& db,
                                                      const sim::Track& track,
                                                      const std::string& who) {
  auto kept = db.bestLap(sim::layoutText(track), who);
  if (!kept) return Unexpected{kept.error()};
  if (!*kept) return std::optional<KeptBest>();
  const standings::KeptLap& k = **kept;
  const std::string label =
      printable(k.driver, 80) + "'s personal best in " + printable(k.car, 80) + " (" + k.when + ")";
  auto trace = laps::traceFromJson(nlohmann::json::parse(k.trace, nullptr, false));
  if (!trace)
    return Unexpected{db.path() + " keeps " + label + " damaged (" + trace.error() +
                      "): race the track again to keep a new one, or give a record"};
  if (std::abs(trace->length - laps::LapMap(track).lap) > 1)
    return Unexpected{db.path() + " keeps " + label +
                      " for a lap of another length than this track's: race the track again"};
  return std::optional<KeptBest>(KeptBest{std::move(*trace), label});
}

namespace {

Result<view::Ghost, std::string> personalBest(const std::string& who, const sim::Track& track,
                                              standings::Database* db) {
  if (!db)
    return Unexpected{std::string(
        "--ghost best races a personal best the standings keep, and this run keeps none "
        "(--no-db, or no $HOME): give --db FILE, or a record: --ghost FILE[:CAR[:LAP]]")};
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
