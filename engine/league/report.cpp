#include "engine/league/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/core/printable.hpp"
#include "engine/core/svg_chart.hpp"

namespace pitwall::league {

namespace {

// A value as HTML text: a string as printable() shows it (a driver's error may hold any byte).
std::string text(const nlohmann::json& v) {
  if (v.is_string()) return markupEscaped(printable(v.get<std::string>()));
  if (v.is_null()) return "–";
  return markupEscaped(v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

std::string seconds(const nlohmann::json& v) {
  if (!v.is_number()) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v.get<double>());
  return buf;
}

// A heat's lap times, one line per driver: lap number across, seconds up.
std::string chart(nlohmann::json& heat) {
  svg::Chart c;
  c.cssClass = "laps";
  c.ariaLabel = "lap times";
  c.xLabel = "lap";
  c.yUnit = " s";
  c.empty = "no lap was timed";
  std::size_t laps = 0;
  for (auto& r : heat["results"]) {
    svg::Series s;
    s.cssClass = "driver";
    const auto& driver = r["driver"];
    s.label = driver.is_string()
                  ? driver.get<std::string>()
                  : driver.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    const auto& times = r["lapTimes"];
    if (times.is_array()) {
      laps = std::max(laps, times.size());
      for (std::size_t i = 0; i < times.size(); ++i)
        if (times[i].is_number())
          s.points.emplace_back(static_cast<double>(i + 1), times[i].get<double>());
    }
    c.series.push_back(std::move(s));
  }
  for (std::size_t lap = 1; lap <= laps; ++lap)
    c.xTicks.push_back({static_cast<double>(lap), std::to_string(lap)});
  return svg::lineChart(c);
}

}  // namespace

std::string htmlReport(const nlohmann::json& given) {
  // (a copy: operator[] reads a missing key as null there, where on a const one it may not)
  nlohmann::json league = given;
  std::ostringstream h;
  auto& about = league["league"];
  h << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    << "<title>League: " << text(about["title"]) << "</title><style>"
    << "body{font-family:system-ui,sans-serif;margin:2em;max-width:60em}"
    << "table{border-collapse:collapse;margin:.5em 0 1.5em}"
    << "td,th{padding:.2em .7em;border-bottom:1px solid #ddd;text-align:left}"
    << "td.n,th.n{text-align:right}.dnf{color:#a00}section.heat{margin-bottom:2em}"
    << "</style></head><body>\n";
  h << "<h1>League: " << text(about["title"]) << "</h1>\n<p>" << text(about["drivers"])
    << " drivers, " << text(about["heats"]) << " heats of up to " << text(about["cars"])
    << " cars, " << text(about["laps"]) << " laps on " << text(about["track"]) << "; seed "
    << text(about["seed"]) << ". Points per place 25, 18, 15, 12, 10, 8, 6, 4, 2, 1; ties by "
    << "count-back, then qualifying.</p>\n";
  h << "<h2>Standings</h2>\n<table id=\"standings\"><tr><th class=\"n\">Pos</th><th>Driver</th>"
    << "<th class=\"n\">Points</th><th class=\"n\">Heats</th><th class=\"n\">Wins</th>"
    << "<th class=\"n\">Best lap</th><th class=\"n\">Qualifying</th></tr>\n";
  for (auto& s : league["standings"])
    h << "<tr><td class=\"n\">" << text(s["position"]) << "</td><td>" << text(s["driver"])
      << "</td><td class=\"n\">" << text(s["points"]) << "</td><td class=\"n\">" << text(s["heats"])
      << "</td><td class=\"n\">" << text(s["wins"]) << "</td><td class=\"n\">"
      << seconds(s["bestLap"]) << "</td><td class=\"n\">" << seconds(s["qualifying"])
      << "</td></tr>\n";
  h << "</table>\n<h2>Qualifying</h2>\n<table id=\"qualifying\"><tr><th>Driver</th>"
    << "<th class=\"n\">Best lap</th><th>Status</th></tr>\n";
  for (auto& q : league["qualifying"])
    h << "<tr><td>" << text(q["driver"]) << "</td><td class=\"n\">" << seconds(q["bestLap"])
      << "</td><td" << (q.value("status", "") == "finished" ? "" : " class=\"dnf\"") << ">"
      << text(q["status"]) << (q.contains("reason") ? ": " + text(q["reason"]) : "")
      << "</td></tr>\n";
  h << "</table>\n<h2>Heats</h2>\n";
  for (auto& heat : league["heats"]) {
    h << "<section class=\"heat\"><h3>Heat " << text(heat["heat"]) << "</h3>";
    if (heat.contains("error")) {
      h << "<p class=\"dnf\">" << text(heat["error"]) << "</p></section>\n";
      continue;
    }
    h << "<table><tr><th class=\"n\">Pos</th><th>Driver</th><th class=\"n\">Points</th>"
      << "<th class=\"n\">Laps</th><th class=\"n\">Time</th><th class=\"n\">Best lap</th>"
      << "<th>Status</th></tr>";
    for (auto& r : heat["results"])
      h << "<tr><td class=\"n\">" << text(r["position"]) << "</td><td>" << text(r["driver"])
        << "</td><td class=\"n\">" << text(r["points"]) << "</td><td class=\"n\">"
        << text(r["laps"]) << "</td><td class=\"n\">" << seconds(r["totalTime"])
        << "</td><td class=\"n\">" << seconds(r["bestLap"]) << "</td><td"
        << (r.value("status", "") == "finished" ? "" : " class=\"dnf\"") << ">" << text(r["status"])
        << (r.contains("reason") ? ": " + text(r["reason"]) : "") << "</td></tr>";
    h << "</table>" << chart(heat) << "</section>\n";
  }
  h << "</body></html>\n";
  return h.str();
}

}  // namespace pitwall::league
