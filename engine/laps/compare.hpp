#pragma once
// Two or more laps side by side (`pitwall compare`, the view's lap comparison; docs/racing.md
// "Comparing laps"): aligned by distance along the track, not by time — the running time delta
// of each lap to the first against distance, and the time of each section (each straight and each
// corner).
//
// By distance when every piece of every lap sent a position update; otherwise per piece: a real
// car at speed reports no position on most curves, so only the pieces' boundaries (its
// transitions, exact to a frame) are known, and the comparison says so.
#include <string>
#include <vector>

#include "engine/laps/trace.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::laps {

// A part of the lap to time on its own: a run of straights, or of curves turning the same way
// (a corner), in lap order from the line.
struct Section {
  std::string name;                 // "straight 1", "left 1", "right 2", …
  std::size_t first = 0, last = 0;  // pieces k (lap order), inclusive
  double from = 0, to = 0;          // mm from the line
  bool curve = false;
};

std::vector<Section> sections(const sim::Track& track, const LapMap& map);

struct Comparison {
  bool byDistance = true;
  std::string how;                        // one sentence: by distance, or per piece and why
  std::vector<double> distance;           // mm from the line, where the times are given
  std::vector<std::vector<double>> time;  // [lap][i]: s since its line at distance[i]
  // [lap j ≥ 1][i]: lap j's time at distance[i] minus the first lap's (s): rising where lap j
  // loses time; [0] is the first lap against itself (all 0)
  std::vector<std::vector<double>> delta;
  std::vector<std::vector<double>> sectionTimes;  // [section][lap] s
  // [lap][k]: the average speed on piece k along the lane the car last reported (mm/s), from
  // the piece's boundaries: what a per-piece comparison knows of its speed
  std::vector<std::vector<double>> pieceSpeed;
};

// The laps, all on `map`'s track, the first the reference. `step`: mm between the points of a
// comparison by distance.
Comparison compare(const std::vector<const LapTrace*>& laps, const LapMap& map,
                   const std::vector<Section>& sections, double step = 10);

}  // namespace pitwall::laps
