#include "engine/sim/grid.hpp"

#include <algorithm>
#include <cctype>

#include "engine/protocol/anki/advertisement.hpp"

namespace pitwall::sim {

std::uint8_t gridModel(int index) {
  static constexpr std::uint8_t kModels[] = {8, 9, 10, 11, 3, 4, 6, 7, 12, 14, 16, 18};
  return kModels[index % std::size(kModels)];
}

CarSpec gridSpec(const Track& track, int index) {
  CarSpec spec;
  spec.model_id = gridModel(index);
  // The start piece (34) sits just before the finish line; rows of four go back from there.
  std::size_t start = (track.finishIndex() + track.size() - 1) % track.size();
  int row = index / 4;
  spec.piece_index = (start + track.size() * (row / track.size() + 1) - row) % track.size();
  spec.offset_mm = kLaneOffsets[index % 4];
  spec.distance_mm = 60.0 + 20.0 * (index % 4);  // staggered a little, like a real grid
  return spec;
}

int gridCapacity(const Track& track) {
  return 4 * static_cast<int>(track.size());
}

std::string ovalLayoutFor(int cars) {
  // start (2 pieces) + a straights + 2 curves + (a + 1) straights + 2 curves = 2a + 7 pieces.
  int rows = (std::max(cars, 0) + 3) / 4;
  int a = std::max(1, (rows - 7 + 1) / 2);
  auto straights = [](int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += " S";
    return out;
  };
  return "start" + straights(a) + " L L" + straights(a + 1) + " L L";
}

}  // namespace pitwall::sim
