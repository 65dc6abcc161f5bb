#pragma once
// The view's lap comparison (docs/view.md "Comparing two laps"): GET /api/laps lists every car's
// traced laps; GET /api/laps/compare?a=CAR:LAP&b=CAR:LAP compares two of them as `pitwall
// compare` does (engine/laps/compare) and answers its JSON and its SVG charts.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "engine/core/result.hpp"
#include "engine/view/feed.hpp"

namespace pitwall::view {

// {"cars":[{"number","name","laps":[{"lap","time","clean"}]}]}: the laps each car's trace keeps.
nlohmann::json lapList(const Feed& feed);

// The query of /api/laps/compare ("a=1:3&b=2:5"): the comparison as reportJson's object with
// "svg" (the three charts), or a sentence naming what is wrong (a malformed query, a car or lap
// the feed has not, no track).
Result<nlohmann::json, std::string> compareLaps(const Feed& feed, std::string_view query);

}  // namespace pitwall::view
