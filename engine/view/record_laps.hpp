#pragma once
// The laps of a record as traces (`pitwall compare`, `sim.addGhost`; docs/racing.md
// "Comparing laps"): the record played through the codec, the car model and the view's feed in
// virtual time, on a loop and fleet of its own, as `pitwall replay` plays it, so a lap here is a
// lap the replay summary and the view count. And the one lap someone asked for by
// FILE[:CAR[:LAP]], or a sentence saying what the record has instead.
#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/laps/trace.hpp"
#include "engine/record/record_reader.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"

namespace pitwall::view {

struct RecordedCarLaps {
  int number = 0;  // the record's car number
  std::string name;
  std::vector<laps::LapTrace> laps;  // its whole laps (clean: forward, on the map), in order
};

struct RecordLaps {
  std::string file;  // as given, for sentences
  sim::Track track;
  std::string layout;  // the track's layout text: laps compared or raced share it
  std::vector<RecordedCarLaps> cars;
};

// `in` holds the record's frames from its start; `summary` is scanRecord's of it.
RecordLaps playLaps(std::istream& in, const RecordSummary& summary, const sim::Track& track,
                    std::string file);

// A lap asked for: the car (its recorded number or name; empty: the record's first car) and the
// lap (its number; 0: the car's best).
struct LapAsk {
  std::string car;
  int lap = 0;
};
// Splits FILE[:CAR[:LAP]] where the longest prefix that exists as a file ends (a name may hold
// ':'); a sentence when no prefix does, or LAP is neither a number from 1 nor `best`.
Result<std::pair<std::string, LapAsk>, std::string> splitLapSpec(const std::string& spec);

struct PickedLap {
  const laps::LapTrace* trace = nullptr;
  const RecordedCarLaps* car = nullptr;
  std::string label;  // "a.jsonl car 1 (groundshock) lap 3"
};
Result<PickedLap, std::string> pickLap(const RecordLaps& record, const LapAsk& ask);

// A record file read for its laps (a timed record; captures without times are for `replay`):
// on `track`, else the layout the record keeps. A file over `maxBytes` is refused unread.
Result<RecordLaps, std::string> readRecordLaps(const std::string& path,
                                               const std::optional<std::string>& track,
                                               std::uintmax_t maxBytes);

// The simulator's ghost of the lap `ask` asks for in the record at `path` (sim.addGhost;
// docs/simulator.md "Ghosts"), on `track`: a car spec standing at the finish line
// in the lap's first lane, named "ghost" (or ghost2, … when `taken` has it), and what it drives
// ("a.jsonl car 1 (skull) lap 3, 4.465 s"). A sentence when the record is over `maxBytes`, was
// driven on another track, lacks the lap, or its lap is faster than any car.
struct Ghost {
  sim::CarSpec spec;
  std::string what;
};
Result<Ghost, std::string> ghostSpec(const std::string& path, const LapAsk& ask,
                                     const sim::Track& track, const std::vector<std::string>& taken,
                                     std::uintmax_t maxBytes);
// The same of a lap at hand (a personal best the standings keep), `label` naming it, on the
// track it was driven on.
Result<Ghost, std::string> ghostOf(const laps::LapTrace& lap, const std::string& label,
                                   const sim::Track& track, const std::vector<std::string>& taken);

}  // namespace pitwall::view
