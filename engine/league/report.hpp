#pragma once
// A league's HTML report (pitwall league --report FILE.html, docs/league.md): the standings,
// qualifying, every heat with a lap-time chart, in one file that opens from the disk — no script,
// no network: the charts are SVG drawn here. From the league's JSON (the --results form).
#include <nlohmann/json.hpp>
#include <string>

namespace pitwall::league {

std::string htmlReport(const nlohmann::json& league);

}  // namespace pitwall::league
