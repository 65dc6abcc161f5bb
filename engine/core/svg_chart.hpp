#pragma once
// A line chart as SVG text, for the reports pitwall writes (a league's lap times, `pitwall
// compare`'s speed and time-delta traces): axes, a few labelled ticks, one polyline per series and
// a legend. Nothing but text: no fonts measured, no I/O; every label is escaped.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pitwall::svg {

// Series colours (Okabe–Ito: told apart by colour-blind readers too), in the order series take
// them.
inline constexpr const char* kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                           "#E69F00", "#56B4E9", "#F0E442", "#000000"};

struct Series {
  std::string label;                              // the legend's text
  std::vector<std::pair<double, double>> points;  // (x, y), in x order; NaN y: a gap
  std::string cssClass;                           // the polyline's class
  bool steps = false;  // a value holds until the next point (per-piece values)
};

struct Tick {
  double at = 0;
  std::string label;
};

struct Chart {
  double width = 520, height = 220;
  double left = 52, right = 120, top = 12, bottom = 30;
  std::string cssClass;          // the <svg>'s class
  std::string ariaLabel;         // what it shows, for a screen reader
  std::string xLabel;            // under the x axis
  std::string yFormat = "%.2f";  // printf format of a y tick's number (then yUnit)
  std::string yUnit;
  std::string empty = "no data";  // shown when no series has a point
  std::vector<Tick> xTicks;       // none: the x range's ends and middle, as %.0f
  std::optional<double> yLine;    // a horizontal rule (0 of a delta)
  // Shaded x ranges behind the lines (a track's curves), each with a title shown on hover.
  struct Band {
    double from = 0, to = 0;
    std::string title;
  };
  std::vector<Band> bands;
  double minYSpan = 0.1;  // the y range is at least this tall, about its middle
  std::vector<Series> series;
};

std::string lineChart(const Chart& chart);

}  // namespace pitwall::svg
