#include "engine/protocol/anki/optical_code.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

using namespace pitwall::anki::optical;

namespace {

// What a reader driving the piece backwards sees: the strokes in reverse, left and right swapped.
std::vector<Stroke> backwards(std::span<const Stroke> forward) {
  std::vector<Stroke> out;
  for (auto it = forward.rbegin(); it != forward.rend(); ++it) out.push_back({it->right, it->left});
  return out;
}

}  // namespace

TEST_CASE("optical code: every piece and location id reads back the same from both directions") {
  for (int piece = 0; piece <= kMaxId; ++piece)
    for (int location = 0; location <= kMaxId; ++location) {
      auto strokes = encodeSection(piece, location);
      auto fwd = decodeSection(strokes);
      auto back = decodeSection(backwards(strokes));
      REQUIRE(fwd);
      REQUIRE(back);
      CHECK(fwd->piece_id == piece);
      CHECK(fwd->location_id == location);
      CHECK_FALSE(fwd->reversed);
      CHECK(back->piece_id == piece);
      CHECK(back->location_id == location);
      CHECK(back->reversed);
    }
  // the piece id is on the left going forward, most significant bit first
  auto s = encodeSection(0b1000001, 0);
  CHECK(s[1].left == Width::Thick);
  CHECK(s[2].left == Width::Thin);
  CHECK(s[7].left == Width::Thick);
  CHECK(s[1].right == Width::Thin);
}

TEST_CASE("optical code: a damaged section is an error that says what is wrong, never a wrong id") {
  auto good = encodeSection(36, 25);
  std::vector<Stroke> v(good.begin(), good.end());
  CHECK(decodeSection(std::span(v).first(8)).error().find("8 strokes") != std::string::npos);
  auto missing = v;
  missing[4].right = Width::None;
  CHECK(decodeSection(missing).error() ==
        "bit 4 is none on the location side, where a bit is thin (0) or thick (1)");
  auto noBoundary = v;
  noBoundary[0] = {Width::Thick, Width::Thick};
  CHECK(decodeSection(noBoundary).error().find("no boundary") != std::string::npos);
  // random strokes: an error or a reading, never a crash; a reading only from well-formed ones
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    std::vector<Stroke> r(static_cast<std::size_t>(rng() % 12));
    for (auto& st : r) st = {Width(rng() % 4), Width(rng() % 4)};
    auto d = decodeSection(r);
    if (d)
      CHECK(encodeSection(d->piece_id, d->location_id) ==
                 (d->reversed ? [&] {
                   auto b = backwards(r);
                   std::array<Stroke, kStrokes> a;
                   std::copy(b.begin(), b.end(), a.begin());
                   return a;
                 }()
                              : [&] {
                                  std::array<Stroke, kStrokes> a;
                                  std::copy(r.begin(), r.end(), a.begin());
                                  return a;
                                }()));
  }
}
