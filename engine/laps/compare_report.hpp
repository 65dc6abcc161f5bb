#pragma once
// A comparison of laps told (`pitwall compare`, docs/racing.md "Comparing laps"): a table of the
// sections in the terminal, the same as JSON, and three charts against distance — speed, the time
// delta to the first lap, the lane — as SVG, or an HTML page with the table and the charts.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/laps/compare.hpp"

namespace pitwall::laps {

struct ComparedLap {
  std::string label;  // "run1.jsonl car 1 (groundshock) lap 3"
  const LapTrace* trace = nullptr;
};

struct Report {
  std::vector<ComparedLap> laps;  // the first is the reference
  std::vector<Section> sections;
  Comparison comparison;
  std::string track;  // its name
};

std::string reportText(const Report& report);
nlohmann::ordered_json reportJson(const Report& report);
std::string reportSvg(const Report& report);   // one SVG: the three charts, stacked
std::string reportHtml(const Report& report);  // a page of its own: the table and the charts

}  // namespace pitwall::laps
