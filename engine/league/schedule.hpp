#pragma once
// A league's heats (docs/league.md "Heats"): which drivers race together, drawn so that every
// driver meets every other. Pure: numbers in, numbers out; the same for the same seed.
#include <cstdint>
#include <vector>

namespace pitwall::league {

// Heats of `perHeat` drivers (0..drivers-1) for `rounds` rounds: in each round every pair of
// drivers races together in at least one heat. Each heat is greedy: it starts with the driver
// who has most pairs left to meet (then the one who raced least, then a seeded draw) and adds
// the driver who meets most new rivals there (same ties). With fewer drivers than `perHeat`,
// one heat of all. Within a heat, drivers are in the order they were drawn.
std::vector<std::vector<int>> drawHeats(int drivers, int perHeat, int rounds, std::uint64_t seed);

// The heats a shard runs (--shard K/N, 1 ≤ K ≤ N): heat i belongs to shard (i mod N) + 1.
bool inShard(std::size_t heat, int shard, int shards);

}  // namespace pitwall::league
