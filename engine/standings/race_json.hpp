#pragma once
// A race's results as JSON: what the race library hands over (pitwall.keepResults) and what an
// unsaved file holds (keeper.hpp) — {kind, number, track, laps, entries: [{number, driver, car,
// file, position, finished, status, reason, laps, bestLap, totalTime, lapTimes}]}.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/standings/database.hpp"

namespace pitwall::standings {

nlohmann::json toJson(const Race& race);
// A sentence naming the field and its value when the JSON is not a race.
Result<Race, std::string> raceFromJson(const nlohmann::json& json);

nlohmann::json toJson(const Event& event);
Result<Event, std::string> eventFromJson(const nlohmann::json& json);

}  // namespace pitwall::standings
