#include "engine/league/scoring.hpp"

#include <algorithm>
#include <array>

namespace pitwall::league {

namespace {

// a < b for times where none is worse than any
bool faster(const std::optional<double>& a, const std::optional<double>& b) {
  if (a && b) return *a < *b;
  return a.has_value() && !b.has_value();
}

}  // namespace

int pointsFor(int position, bool finished) {
  static constexpr std::array<int, 10> kPoints = {25, 18, 15, 12, 10, 8, 6, 4, 2, 1};
  if (!finished || position < 1 || position > static_cast<int>(kPoints.size())) return 0;
  return kPoints[static_cast<std::size_t>(position - 1)];
}

std::vector<Standing> standings(int drivers, const std::vector<std::vector<Place>>& heats,
                                const std::vector<std::optional<double>>& qualifying) {
  std::vector<Standing> table(static_cast<std::size_t>(std::max(drivers, 0)));
  for (int d = 0; d < drivers; ++d) {
    auto& s = table[static_cast<std::size_t>(d)];
    s.driver = d;
    if (static_cast<std::size_t>(d) < qualifying.size()) s.qualifying = qualifying[d];
  }
  std::size_t deepest = 0;
  for (const auto& heat : heats)
    for (const Place& p : heat) {
      if (p.driver < 0 || p.driver >= drivers) continue;
      auto& s = table[static_cast<std::size_t>(p.driver)];
      ++s.heats;
      s.points += pointsFor(p.position, p.finished);
      // (a place past the number of drivers is none a heat of this league can give: no
      // count-back for it, whatever a database says)
      if (p.finished && p.position >= 1 && p.position <= drivers) {
        ++s.finishes;
        const auto k = static_cast<std::size_t>(p.position - 1);
        if (s.places.size() <= k) s.places.resize(k + 1, 0);
        ++s.places[k];
        deepest = std::max(deepest, k + 1);
      }
      if (faster(p.bestLap, s.bestLap)) s.bestLap = p.bestLap;
    }
  for (auto& s : table) s.places.resize(deepest, 0);
  std::stable_sort(table.begin(), table.end(), [](const Standing& a, const Standing& b) {
    if (a.points != b.points) return a.points > b.points;
    for (std::size_t k = 0; k < a.places.size(); ++k)
      if (a.places[k] != b.places[k]) return a.places[k] > b.places[k];
    if (faster(a.qualifying, b.qualifying) || faster(b.qualifying, a.qualifying))
      return faster(a.qualifying, b.qualifying);
    if (faster(a.bestLap, b.bestLap) || faster(b.bestLap, a.bestLap))
      return faster(a.bestLap, b.bestLap);
    return a.driver < b.driver;
  });
  return table;
}

std::vector<int> gridOrder(const std::vector<int>& heat,
                           const std::vector<std::optional<double>>& qualifying) {
  std::vector<int> grid = heat;
  auto lap = [&](int d) {
    return static_cast<std::size_t>(d) < qualifying.size() ? qualifying[d] : std::nullopt;
  };
  std::stable_sort(grid.begin(), grid.end(), [&](int a, int b) { return faster(lap(a), lap(b)); });
  return grid;
}

}  // namespace pitwall::league
