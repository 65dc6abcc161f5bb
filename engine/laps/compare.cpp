#include "engine/laps/compare.hpp"

#include <cmath>

namespace pitwall::laps {

std::vector<Section> sections(const sim::Track& track, const LapMap& map) {
  std::vector<Section> out;
  int straights = 0, lefts = 0, rights = 0;
  for (std::size_t k = 0; k < map.n; ++k) {
    const int turn = track.piece(map.trackIndex(k)).turn;
    if (!out.empty()) {
      Section& last = out.back();
      const int lastTurn = track.piece(map.trackIndex(last.last)).turn;
      if (lastTurn == turn) {
        last.last = k;
        last.to = map.start[k] + map.length[k];
        continue;
      }
    }
    Section s;
    s.first = s.last = k;
    s.from = map.start[k];
    s.to = map.start[k] + map.length[k];
    s.curve = turn != 0;
    s.name = turn == 0  ? "straight " + std::to_string(++straights)
             : turn > 0 ? "left " + std::to_string(++lefts)
                        : "right " + std::to_string(++rights);
    out.push_back(std::move(s));
  }
  return out;
}

Comparison compare(const std::vector<const LapTrace*>& laps, const LapMap& map,
                   const std::vector<Section>& sections, double step) {
  Comparison c;
  std::size_t unreported = 0;
  for (const LapTrace* lap : laps)
    for (bool reported : lap->pieceReported) unreported += reported ? 0 : 1;
  c.byDistance = unreported == 0;
  if (c.byDistance) {
    c.how = "aligned by distance: every piece of every lap sent its position";
    const double s = step > 0 ? step : 10;
    const auto count = static_cast<std::size_t>(std::ceil(map.lap / s));
    for (std::size_t i = 0; i <= count; ++i)
      c.distance.push_back(std::min(map.lap, static_cast<double>(i) * s));
  } else {
    c.how = "per piece: " + std::to_string(unreported) +
            " pieces of these laps sent no position (as a real car on a curve at speed), so "
            "the time is known at the pieces' boundaries only";
    for (std::size_t k = 0; k <= map.n; ++k)
      c.distance.push_back(k < map.n ? map.start[k] : map.lap);
  }
  auto timeAt = [&](const LapTrace& lap, std::size_t i) {
    if (c.byDistance) return lap.timeAt(c.distance[i]);
    return lap.enteredAt(i, map);  // distance[i] is piece i's start (or the lap's end)
  };
  for (const LapTrace* lap : laps) {
    std::vector<double> t(c.distance.size());
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = timeAt(*lap, i);
    c.time.push_back(std::move(t));
  }
  for (const auto& t : c.time) {
    std::vector<double> d(t.size());
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = t[i] - c.time.front()[i];
    c.delta.push_back(std::move(d));
  }
  for (const LapTrace* lap : laps) {
    std::vector<double> v(map.n);
    for (std::size_t k = 0; k < map.n; ++k) {
      const double dt = lap->enteredAt(k + 1, map) - lap->enteredAt(k, map);
      v[k] = dt > 0 ? map.pieces[k].length(lap->offsetOn(k, map)) / dt : NAN;
    }
    c.pieceSpeed.push_back(std::move(v));
  }
  for (const Section& s : sections) {
    std::vector<double> times;
    for (const LapTrace* lap : laps)
      times.push_back(lap->enteredAt(s.last + 1, map) - lap->enteredAt(s.first, map));
    c.sectionTimes.push_back(std::move(times));
  }
  return c;
}

}  // namespace pitwall::laps
