#pragma once
// A lap trace as JSON, to keep (a personal best in the standings, docs/racing.md "Personal
// bests") and to read back. What is read is checked as any file's content is: a trace that is
// not whole, out of order or too long is a sentence, never a crash or a ghost that flies.
#include <nlohmann/json.hpp>
#include <string>

#include "engine/core/result.hpp"
#include "engine/laps/trace.hpp"

namespace pitwall::laps {

// {"lap", "time", "length", "points": [[t, distance, speed|null, offset|null], …],
//  "entered": [s|null by piece], "reported": [0|1 by piece]}; times and distances to 1/1000.
nlohmann::json traceJson(const LapTrace& trace);

// The most points a kept trace may have (a lap of 5 ms points is 2000 a 10 s lap).
inline constexpr std::size_t kMaxTracePoints = 100000;

Result<LapTrace, std::string> traceFromJson(const nlohmann::json& json);

}  // namespace pitwall::laps
