#pragma once
// --ghost for `pitwall run` (docs/racing.md "Racing a ghost"): FILE[:CAR[:LAP]], a lap of a
// record; `best`, the fastest personal best the standings keep on the run's track; `best:NAME`,
// the fastest of that driver or car. What it names becomes the simulated ghost's car — or a
// sentence saying what is missing, before any car is connected.
#include <optional>
#include <string>

#include "engine/core/result.hpp"
#include "engine/sim/track.hpp"
#include "engine/standings/database.hpp"
#include "engine/view/record_laps.hpp"

namespace pitwall::cli {

// The largest record --ghost reads: it is played before the race, in about 26 µs a line
// (docs/performance.md "Ghosts"), so 64 MiB is some seconds.
inline constexpr std::uintmax_t kMaxGhostRecordBytes = std::uintmax_t{64} << 20;

// The fastest personal best `db` keeps on `track` (of the driver or car `who`; empty: anyone's),
// and whose it is ("alice's personal best in skull (2026-12-01T19:02:11Z)"); none when it keeps
// none; a sentence when the kept lap is damaged or of another length.
struct KeptBest {
  laps::LapTrace lap;
  std::string label;
};
Result<std::optional<KeptBest>, std::string> keptBest(standings::Database& db,
                                                      const sim::Track& track,
                                                      const std::string& who);

// `db`: the standings the run keeps (nullptr: none).
Result<view::Ghost, std::string> resolveGhost(const std::string& spec, const sim::Track& track,
                                              standings::Database* db);

}  // namespace pitwall::cli
