#include "engine/league/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/core/printable.hpp"

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

// The colours of a heat's lines (Okabe–Ito: told apart by colour-blind readers too).
constexpr const char* kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                    "#E69F00", "#56B4E9", "#F0E442", "#000000"};

// A heat's lap times, one line per driver: lap number across, seconds up.
std::string chart(nlohmann::json& heat) {
  const double width = 520, height = 220, left = 52, right = 120, top = 12, bottom = 30;
  double lo = INFINITY, hi = -INFINITY;
  std::size_t laps = 0;
  for (auto& r : heat["results"]) {
    const auto& times = r["lapTimes"];
    if (!times.is_array()) continue;
    laps = std::max(laps, times.size());
    for (const auto& t : times)
      if (t.is_number()) {
        lo = std::min(lo, t.get<double>());
        hi = std::max(hi, t.get<double>());
      }
  }
  std::ostringstream svg;
  svg << "<svg class=\"laps\" viewBox=\"0 0 " << width << ' ' << height << "\" width=\"" << width
      << "\" height=\"" << height << "\" role=\"img\" aria-label=\"lap "
      << "times\">";
  if (laps == 0 || !std::isfinite(lo)) {
    svg << "<text x=\"" << left << "\" y=\"" << height / 2 << "\">no lap was timed</text></svg>";
    return svg.str();
  }
  if (hi - lo < 0.05) {
    lo -= 0.05;
    hi += 0.05;
  }
  const double plotW = width - left - right, plotH = height - top - bottom;
  auto x = [&](std::size_t lap) {
    return left + (laps == 1 ? plotW / 2 : plotW * static_cast<double>(lap) / (laps - 1));
  };
  auto y = [&](double t) { return top + plotH * (hi - t) / (hi - lo); };
  svg << "<g class=\"axes\" stroke=\"#888\"><line x1=\"" << left << "\" y1=\"" << top << "\" x2=\""
      << left << "\" y2=\"" << top + plotH << "\"/><line x1=\"" << left << "\" y1=\"" << top + plotH
      << "\" x2=\"" << left + plotW << "\" y2=\"" << top + plotH << "\"/></g>";
  char label[64];
  for (double t : {lo, (lo + hi) / 2, hi}) {
    std::snprintf(label, sizeof label, "%.2f s", t);
    svg << "<text x=\"" << left - 4 << "\" y=\"" << y(t) + 4
        << "\" text-anchor=\"end\" font-size=\"10\">" << label << "</text>";
  }
  for (std::size_t lap = 0; lap < laps; ++lap)
    svg << "<text x=\"" << x(lap) << "\" y=\"" << top + plotH + 14
        << "\" text-anchor=\"middle\" font-size=\"10\">" << lap + 1 << "</text>";
  svg << "<text x=\"" << left + plotW / 2 << "\" y=\"" << height - 2
      << "\" text-anchor=\"middle\" font-size=\"10\">lap</text>";
  std::size_t line = 0;
  for (auto& r : heat["results"]) {
    const char* colour = kColours[line % std::size(kColours)];
    const auto& times = r["lapTimes"];
    std::ostringstream points;
    std::size_t n = 0;
    if (times.is_array())
      for (std::size_t i = 0; i < times.size(); ++i)
        if (times[i].is_number()) {
          points << (n++ ? " " : "") << x(i) << ',' << y(times[i].get<double>());
        }
    if (n > 0)
      svg << "<polyline class=\"driver\" fill=\"none\" stroke-width=\"2\" stroke=\"" << colour
          << "\" points=\"" << points.str() << "\"/>";
    svg << "<text x=\"" << left + plotW + 8 << "\" y=\"" << top + 12 + 14.0 * line
        << "\" font-size=\"11\" fill=\"" << colour << "\">" << text(r["driver"]) << "</text>";
    ++line;
  }
  svg << "</svg>";
  return svg.str();
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
