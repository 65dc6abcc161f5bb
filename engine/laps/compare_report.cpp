#include "engine/laps/compare_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/core/printable.hpp"
#include "engine/core/svg_chart.hpp"

namespace pitwall::laps {

namespace {

std::string fixed(double v, int decimals = 3, bool sign = false) {
  if (!std::isfinite(v)) return "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, sign ? "%+.*f" : "%.*f", decimals, v);
  return buf;
}

nlohmann::ordered_json number(double v, double scale = 1e6) {
  if (!std::isfinite(v)) return nullptr;
  const double r = std::round(v * scale) / scale;
  return r == 0 ? 0.0 : r;
}

svg::Chart base(const Report& r, const std::string& cls, const std::string& what) {
  svg::Chart c;
  c.width = 720;
  c.height = 200;
  c.right = 220;
  c.cssClass = cls;
  c.ariaLabel = what + " against distance";
  c.xLabel = "distance from the line (mm); shaded: curves";
  for (const Section& s : r.sections)
    if (s.curve) c.bands.push_back({s.from, s.to, s.name});
  c.left = 76;
  // every chart over the whole lap, a tick each metre
  const double lap = r.sections.empty() ? 0 : r.sections.back().to;
  for (double at = 0; at < lap - 300; at += 1000)
    c.xTicks.push_back({at, std::to_string(static_cast<int>(at))});
  c.xTicks.push_back({lap, std::to_string(static_cast<int>(std::lround(lap)))});
  return c;
}

std::vector<svg::Chart> charts(const Report& r) {
  const Comparison& cmp = r.comparison;
  svg::Chart speed = base(r, "speed", "speed");
  speed.yFormat = "%.0f";
  speed.yUnit = " mm/s";
  speed.minYSpan = 100;
  speed.empty = "no lap reported its speed";
  svg::Chart delta = base(r, "delta", "time delta to the first lap");
  delta.yFormat = "%+.3f";
  delta.yUnit = " s";
  delta.yLine = 0;
  delta.minYSpan = 0.02;
  svg::Chart lane = base(r, "lane", "lane offset");
  lane.yFormat = "%.0f";
  lane.yUnit = " mm";
  lane.minYSpan = 20;
  lane.empty = "no lap reported its lane";
  for (std::size_t j = 0; j < r.laps.size() && j < cmp.time.size(); ++j) {
    const LapTrace& t = *r.laps[j].trace;
    svg::Series s{r.laps[j].label, {}, "lap", false};
    svg::Series l = s;
    if (cmp.byDistance) {
      for (const TracePoint& p : t.points)
        if (std::isfinite(p.speed)) s.points.emplace_back(p.distance, p.speed);
    } else {
      // per piece: the average speed along each piece's centre line, from its boundaries
      s.steps = true;
      for (std::size_t k = 0; k + 1 < cmp.distance.size() && k < cmp.pieceSpeed[j].size(); ++k)
        s.points.emplace_back(cmp.distance[k], cmp.pieceSpeed[j][k]);
      if (!s.points.empty()) s.points.emplace_back(cmp.distance.back(), s.points.back().second);
    }
    for (const TracePoint& p : t.points)
      if (std::isfinite(p.offset)) l.points.emplace_back(p.distance, p.offset);
    speed.series.push_back(std::move(s));
    lane.series.push_back(std::move(l));
    svg::Series d{r.laps[j].label, {}, "lap", false};
    for (std::size_t i = 0; i < cmp.distance.size(); ++i)
      d.points.emplace_back(cmp.distance[i], cmp.delta[j][i]);
    delta.series.push_back(std::move(d));
  }
  if (!cmp.byDistance) speed.ariaLabel = "average speed of each piece against distance";
  return {speed, delta, lane};
}

// The table's rows: each section's times (its name, "FROM-TO" in mm), then the lap's.
template <class Row>
void eachRow(const Report& r, const char* dash, Row row) {
  const Comparison& cmp = r.comparison;
  for (std::size_t s = 0; s < r.sections.size() && s < cmp.sectionTimes.size(); ++s)
    row(r.sections[s].name, fixed(r.sections[s].from, 0) + dash + fixed(r.sections[s].to, 0),
        cmp.sectionTimes[s]);
  std::vector<double> totals;
  for (const auto& l : r.laps) totals.push_back(l.trace->time);
  row("lap", "", totals);
}

const char* const kTitles[] = {"Speed", "Time delta to the first lap (rising: losing time)",
                               "Lane (mm right of the centre)"};

}  // namespace

std::string reportText(const Report& r) {
  std::ostringstream out;
  const Comparison& cmp = r.comparison;
  for (std::size_t j = 0; j < r.laps.size(); ++j) {
    const LapTrace& t = *r.laps[j].trace;
    out << static_cast<char>('A' + j % 26) << "  " << printable(r.laps[j].label) << "  "
        << fixed(t.time) << " s";
    if (j > 0) out << "  " << fixed(t.time - r.laps[0].trace->time, 3, true) << " s";
    out << "\n";
  }
  out << cmp.how << "\n\n";
  char line[160];
  std::snprintf(line, sizeof line, "%-12s %13s", "SECTION", "MM");
  out << line;
  for (std::size_t j = 0; j < r.laps.size(); ++j) {
    const std::string letter(1, static_cast<char>('A' + j % 26));
    std::snprintf(line, sizeof line, "  %8s", letter.c_str());
    out << line;
    if (j > 0) {
      std::snprintf(line, sizeof line, " %7s", (letter + "-A").c_str());
      out << line;
    }
  }
  out << "\n";
  auto row = [&](const std::string& name, const std::string& mm, const std::vector<double>& times) {
    std::snprintf(line, sizeof line, "%-12s %13s", name.c_str(), mm.c_str());
    out << line;
    for (std::size_t j = 0; j < times.size(); ++j) {
      std::snprintf(line, sizeof line, "  %8s", fixed(times[j]).c_str());
      out << line;
      if (j > 0) {
        std::snprintf(line, sizeof line, " %7s", fixed(times[j] - times[0], 3, true).c_str());
        out << line;
      }
    }
    out << "\n";
  };
  eachRow(r, "-", row);
  return out.str();
}

nlohmann::ordered_json reportJson(const Report& r) {
  const Comparison& cmp = r.comparison;
  nlohmann::ordered_json j;
  j["track"] = r.track;
  j["byDistance"] = cmp.byDistance;
  j["how"] = cmp.how;
  j["laps"] = nlohmann::ordered_json::array();
  for (const auto& l : r.laps)
    j["laps"].push_back({{"label", l.label},
                         {"lap", l.trace->lap},
                         {"time", number(l.trace->time)},
                         {"everyPieceReported", l.trace->everyPieceReported()}});
  j["sections"] = nlohmann::ordered_json::array();
  for (std::size_t s = 0; s < r.sections.size() && s < cmp.sectionTimes.size(); ++s) {
    nlohmann::ordered_json times = nlohmann::ordered_json::array();
    for (double t : cmp.sectionTimes[s]) times.push_back(number(t));
    j["sections"].push_back({{"name", r.sections[s].name},
                             {"from", number(r.sections[s].from, 10)},
                             {"to", number(r.sections[s].to, 10)},
                             {"curve", r.sections[s].curve},
                             {"times", std::move(times)}});
  }
  j["distance"] = nlohmann::ordered_json::array();
  for (double d : cmp.distance) j["distance"].push_back(number(d, 10));
  j["delta"] = nlohmann::ordered_json::array();
  for (const auto& d : cmp.delta) {
    nlohmann::ordered_json row = nlohmann::ordered_json::array();
    for (double v : d) row.push_back(number(v));
    j["delta"].push_back(std::move(row));
  }
  return j;
}

std::string reportSvg(const Report& r) {
  const auto cs = charts(r);
  double y = 0;
  std::ostringstream svg;
  const double width = cs.front().width, title = 20;
  double height = 0;
  for (const auto& c : cs) height += title + c.height;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"compare\" viewBox=\"0 0 " << width
      << ' ' << height << "\" width=\"" << width << "\" height=\"" << height
      << "\" font-family=\"sans-serif\"><rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>";
  for (std::size_t i = 0; i < cs.size(); ++i) {
    svg << "<text x=\"8\" y=\"" << y + 15 << "\" font-size=\"13\" font-weight=\"bold\">"
        << kTitles[i] << "</text><g transform=\"translate(0 " << y + title << ")\">"
        << svg::lineChart(cs[i]) << "</g>";
    y += title + cs[i].height;
  }
  svg << "</svg>";
  return svg.str();
}

std::string reportHtml(const Report& r) {
  const auto cs = charts(r);
  std::ostringstream h;
  h << "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>pitwall compare: "
    << markupEscaped(printable(r.track))
    << "</title><style>body{font-family:sans-serif;margin:1.5em;max-width:60em}"
       "table{border-collapse:collapse}td,th{padding:.2em .6em;text-align:right}"
       "td:first-child,th:first-child{text-align:left}tr:nth-child(even){background:#f4f4f4}"
       ".lose{color:#b00}.gain{color:#070}</style></head><body><h1>Lap comparison</h1><p>"
    << markupEscaped(printable(r.track)) << ". " << markupEscaped(r.comparison.how)
    << ".</p><table class=\"sections\"><tr><th>section</th><th>mm</th>";
  for (std::size_t j = 0; j < r.laps.size(); ++j)
    h << "<th>" << markupEscaped(printable(r.laps[j].label)) << "</th>";
  h << "</tr>";
  auto row = [&](const std::string& name, const std::string& mm, const std::vector<double>& t) {
    h << "<tr><td>" << markupEscaped(name) << "</td><td>" << mm << "</td>";
    for (std::size_t j = 0; j < t.size(); ++j) {
      h << "<td>" << fixed(t[j]);
      if (j > 0) {
        const double d = t[j] - t[0];
        h << " <span class=\"" << (d > 0 ? "lose" : "gain") << "\">" << fixed(d, 3, true)
          << "</span>";
      }
      h << "</td>";
    }
    h << "</tr>";
  };
  eachRow(r, "–", row);
  h << "</table>";
  for (std::size_t i = 0; i < cs.size(); ++i)
    h << "<h2>" << kTitles[i] << "</h2>" << svg::lineChart(cs[i]);
  h << "</body></html>\n";
  return h.str();
}

}  // namespace pitwall::laps
