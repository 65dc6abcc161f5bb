#include "engine/league/schedule.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <tuple>

namespace pitwall::league {

std::vector<std::vector<int>> drawHeats(int drivers, int perHeat, int rounds, std::uint64_t seed) {
  std::vector<std::vector<int>> heats;
  if (drivers <= 0 || perHeat <= 0 || rounds <= 0) return heats;
  if (perHeat == 1 || drivers <= perHeat) {  // nobody to meet, or one heat meets everyone
    for (int r = 0; r < rounds; ++r) {
      if (perHeat == 1) {
        for (int d = 0; d < drivers; ++d) heats.push_back({d});
      } else {
        std::vector<int> all(static_cast<std::size_t>(drivers));
        std::iota(all.begin(), all.end(), 0);
        heats.push_back(all);
      }
    }
    return heats;
  }
  std::mt19937_64 rng(seed);
  std::vector<int> raced(static_cast<std::size_t>(drivers), 0);
  auto at = [drivers](int a, int b) { return static_cast<std::size_t>(a * drivers + b); };
  for (int r = 0; r < rounds; ++r) {
    // pairs still to meet this round, and each driver's count of them
    std::vector<char> left(static_cast<std::size_t>(drivers * drivers), 0);
    std::vector<int> leftOf(static_cast<std::size_t>(drivers), drivers - 1);
    int pairsLeft = drivers * (drivers - 1) / 2;
    for (int a = 0; a < drivers; ++a)
      for (int b = 0; b < drivers; ++b) left[at(a, b)] = a != b;
    std::vector<int> draw(static_cast<std::size_t>(drivers));  // the seeded tie-break
    std::iota(draw.begin(), draw.end(), 0);
    std::shuffle(draw.begin(), draw.end(), rng);
    std::vector<int> rank(static_cast<std::size_t>(drivers));
    for (int i = 0; i < drivers; ++i) rank[static_cast<std::size_t>(draw[i])] = i;
    while (pairsLeft > 0) {
      std::vector<int> heat;
      std::vector<char> in(static_cast<std::size_t>(drivers), 0);
      // the first: most pairs left, then raced least, then the draw
      int first = -1;
      for (int d = 0; d < drivers; ++d) {
        auto key = [&](int x) { return std::make_tuple(-leftOf[x], raced[x], rank[x]); };
        if (first < 0 || key(d) < key(first)) first = d;
      }
      heat.push_back(first);
      in[first] = 1;
      while (static_cast<int>(heat.size()) < perHeat) {
        int best = -1;
        int bestNew = 0;
        for (int d = 0; d < drivers; ++d) {
          if (in[d]) continue;
          int fresh = 0;
          for (int h : heat) fresh += left[at(h, d)];
          auto key = [&](int x, int n) { return std::make_tuple(-n, raced[x], rank[x]); };
          if (best < 0 || key(d, fresh) < key(best, bestNew)) {
            best = d;
            bestNew = fresh;
          }
        }
        heat.push_back(best);
        in[best] = 1;
      }
      for (std::size_t i = 0; i < heat.size(); ++i) {
        ++raced[heat[i]];
        for (std::size_t j = i + 1; j < heat.size(); ++j) {
          const int a = heat[i], b = heat[j];
          if (!left[at(a, b)]) continue;
          left[at(a, b)] = left[at(b, a)] = 0;
          --leftOf[a];
          --leftOf[b];
          --pairsLeft;
        }
      }
      heats.push_back(std::move(heat));
    }
  }
  return heats;
}

bool inShard(std::size_t heat, int shard, int shards) {
  return shards <= 1 || static_cast<int>(heat % static_cast<std::size_t>(shards)) + 1 == shard;
}

}  // namespace pitwall::league
