#include "engine/core/svg_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "engine/core/printable.hpp"

namespace pitwall::svg {

namespace {

std::string number(const std::string& format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format.c_str(), v);
  return buf;
}

std::string escaped(const std::string& text) {
  return markupEscaped(printable(text));
}

}  // namespace

std::string lineChart(const Chart& c) {
  double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
  for (const auto& s : c.series)
    for (const auto& [x, y] : s.points) {
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      xlo = std::min(xlo, x);
      xhi = std::max(xhi, x);
      ylo = std::min(ylo, y);
      yhi = std::max(yhi, y);
    }
  for (const auto& t : c.xTicks) {
    xlo = std::min(xlo, t.at);
    xhi = std::max(xhi, t.at);
  }
  std::ostringstream svg;
  svg << "<svg class=\"" << escaped(c.cssClass) << "\" xmlns=\"http://www.w3.org/2000/svg\""
      << " viewBox=\"0 0 " << c.width << ' ' << c.height << "\" width=\"" << c.width
      << "\" height=\"" << c.height << "\" role=\"img\" aria-label=\"" << escaped(c.ariaLabel)
      << "\" font-family=\"sans-serif\">";
  if (!std::isfinite(ylo) || !std::isfinite(xlo)) {
    svg << "<text x=\"" << c.left << "\" y=\"" << c.height / 2 << "\">" << escaped(c.empty)
        << "</text></svg>";
    return svg.str();
  }
  if (c.yLine) {
    ylo = std::min(ylo, *c.yLine);
    yhi = std::max(yhi, *c.yLine);
  }
  if (yhi - ylo < c.minYSpan) {
    const double mid = (yhi + ylo) / 2;
    ylo = mid - c.minYSpan / 2;
    yhi = mid + c.minYSpan / 2;
  }
  if (xhi - xlo <= 0) xhi = xlo + 1;
  const double plotW = c.width - c.left - c.right, plotH = c.height - c.top - c.bottom;
  auto x = [&](double v) { return c.left + plotW * (v - xlo) / (xhi - xlo); };
  auto y = [&](double v) { return c.top + plotH * (yhi - v) / (yhi - ylo); };
  for (const auto& b : c.bands) {
    const double from = std::clamp(b.from, xlo, xhi), to = std::clamp(b.to, xlo, xhi);
    if (to <= from) continue;
    svg << "<rect class=\"band\" x=\"" << x(from) << "\" y=\"" << c.top << "\" width=\""
        << x(to) - x(from) << "\" height=\"" << plotH << "\" fill=\"#eee\"><title>"
        << escaped(b.title) << "</title></rect>";
  }
  svg << "<g class=\"axes\" stroke=\"#888\"><line x1=\"" << c.left << "\" y1=\"" << c.top
      << "\" x2=\"" << c.left << "\" y2=\"" << c.top + plotH << "\"/><line x1=\"" << c.left
      << "\" y1=\"" << c.top + plotH << "\" x2=\"" << c.left + plotW << "\" y2=\"" << c.top + plotH
      << "\"/></g>";
  if (c.yLine)
    svg << "<line class=\"rule\" stroke=\"#bbb\" stroke-dasharray=\"4 3\" x1=\"" << c.left
        << "\" y1=\"" << y(*c.yLine) << "\" x2=\"" << c.left + plotW << "\" y2=\"" << y(*c.yLine)
        << "\"/>";
  for (double t : {ylo, (ylo + yhi) / 2, yhi})
    svg << "<text x=\"" << c.left - 4 << "\" y=\"" << y(t) + 4
        << "\" text-anchor=\"end\" font-size=\"10\">" << escaped(number(c.yFormat, t) + c.yUnit)
        << "</text>";
  std::vector<Tick> ticks = c.xTicks;
  if (ticks.empty())
    for (double t : {xlo, (xlo + xhi) / 2, xhi}) ticks.push_back({t, number("%.0f", t)});
  for (const auto& t : ticks)
    svg << "<text x=\"" << x(t.at) << "\" y=\"" << c.top + plotH + 14
        << "\" text-anchor=\"middle\" font-size=\"10\">" << escaped(t.label) << "</text>";
  svg << "<text x=\"" << c.left + plotW / 2 << "\" y=\"" << c.height - 2
      << "\" text-anchor=\"middle\" font-size=\"10\">" << escaped(c.xLabel) << "</text>";
  std::size_t line = 0;
  for (const auto& s : c.series) {
    const char* colour = kColours[line % std::size(kColours)];
    // one polyline per run of finite points (a NaN is a gap)
    std::ostringstream points;
    std::size_t n = 0;
    auto flush = [&] {
      if (n > 0)
        svg << "<polyline class=\"" << escaped(s.cssClass)
            << "\" fill=\"none\" stroke-width=\"2\" stroke=\"" << colour << "\" points=\""
            << points.str() << "\"/>";
      points.str("");
      n = 0;
    };
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const auto [px, py] = s.points[i];
      if (!std::isfinite(px) || !std::isfinite(py)) {
        flush();
        continue;
      }
      points << (n++ ? " " : "") << x(px) << ',' << y(py);
      if (s.steps && i + 1 < s.points.size() && std::isfinite(s.points[i + 1].first))
        points << ' ' << x(s.points[i + 1].first) << ',' << y(py);
    }
    flush();
    svg << "<text x=\"" << c.left + plotW + 8 << "\" y=\"" << c.top + 12 + 14.0 * line
        << "\" font-size=\"11\" fill=\"" << colour << "\">" << escaped(s.label) << "</text>";
    ++line;
  }
  svg << "</svg>";
  return svg.str();
}

}  // namespace pitwall::svg
