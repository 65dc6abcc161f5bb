#pragma once
// A league's points and standings (docs/league.md "Points and ties"): plain data in, the table
// out. Pure.
#include <optional>
#include <string>
#include <vector>

namespace pitwall::league {

// Points for a place in a heat: 25, 18, 15, 12, 10, 8, 6, 4, 2, 1 for 1st..10th (Formula 1's
// table), 0 after, and 0 for a driver that did not finish.
int pointsFor(int position, bool finished);

// One driver's result in one heat.
struct Place {
  int driver = 0;         // index into the league's drivers
  int position = 0;       // 1-based, as the race director ordered the heat
  bool finished = false;  // took the flag (else DNF)
  std::optional<double> bestLap;
};

// One row of the table.
struct Standing {
  int driver = 0;
  int points = 0;
  int heats = 0;
  int finishes = 0;
  std::vector<int> places;           // places[k]: how many times it finished (k+1)th
  std::optional<double> bestLap;     // its best lap in any heat
  std::optional<double> qualifying;  // its best lap in qualifying
};

// The standings of `drivers` drivers from every heat's places and the qualifying laps (one per
// driver, none for a driver that set no time), sorted by the tie rule: points; then more wins,
// then more second places, and so on (count-back); then the better qualifying lap (a time before
// none); then the better race lap; then the driver's index (the league sorts drivers by name).
std::vector<Standing> standings(int drivers, const std::vector<std::vector<Place>>& heats,
                                const std::vector<std::optional<double>>& qualifying);

// The order of a heat's grid: its drivers by qualifying lap, fastest first (a time before none,
// then the order drawn).
std::vector<int> gridOrder(const std::vector<int>& heat,
                           const std::vector<std::optional<double>>& qualifying);

}  // namespace pitwall::league
