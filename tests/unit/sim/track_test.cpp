#include "engine/sim/track.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>

using namespace pitwall;
using namespace pitwall::sim;

namespace {

std::vector<int> ids(const Track& t) {
  std::vector<int> out;
  for (const Piece& p : t.pieces()) out.push_back(p.id);
  return out;
}

std::string errorOf(std::string_view text) {
  auto r = parseLayout(text);
  REQUIRE_FALSE(r.ok());
  return r.error();
}

bool contains(const std::string& s, std::string_view part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("the oval is the start pair, then S L L S S L L, about 4.0 m along its centre") {
  auto oval = namedLayout("oval");
  REQUIRE(oval.ok());
  CHECK(oval->name() == "oval");
  CHECK(ids(*oval) == std::vector<int>{34, 33, 36, 17, 18, 39, 40, 20, 23});
  CHECK(std::abs(oval->lapLength(0) - 4000) <= 1);
  CHECK(oval->finishIndex() == 1);
  CHECK(oval->piece(1).type == anki::PieceType::StartShort);
}

TEST_CASE("piece lengths follow the reference: 560, 340, 220 and quarter circles of 280 mm") {
  auto t = parseLayout("start S L L S S L L");
  REQUIRE(t.ok());
  CHECK(t->piece(0).length(0) == 340);
  CHECK(t->piece(1).length(0) == 220);
  CHECK(t->piece(2).length(50) == 560);
  CHECK(t->piece(3).length(0) == doctest::Approx(280 * std::numbers::pi / 2));
}

TEST_CASE("a curve is longer on its outer lanes: right of a left curve, left of a right curve") {
  Piece left{17, anki::PieceType::Curve, 1};
  Piece right{18, anki::PieceType::Curve, -1};
  CHECK(left.length(68) == doctest::Approx((280 + 68) * std::numbers::pi / 2));
  CHECK(left.length(-68) == doctest::Approx((280 - 68) * std::numbers::pi / 2));
  CHECK(right.length(68) == doctest::Approx((280 - 68) * std::numbers::pi / 2));
  CHECK(right.length(-68) == doctest::Approx((280 + 68) * std::numbers::pi / 2));
  auto oval = namedLayout("oval");
  CHECK(oval->lapLength(68) > oval->lapLength(0));
  CHECK(oval->lapLength(-68) < oval->lapLength(0));
  // 4 left curves: the outer lane gains 4 × 68 × π/2 mm.
  CHECK(oval->lapLength(68) - oval->lapLength(0) == doctest::Approx(4 * 68 * std::numbers::pi / 2));
}

TEST_CASE("a custom layout takes long names, explicit ids and comments") {
  auto t = parseLayout(
      "# a kidney\n"
      "start straight:51 left left S:48 right L:27 L S L  # closes\n",
      "mine");
  REQUIRE(t.ok());
  CHECK(t->name() == "mine");
  CHECK(ids(*t) == std::vector<int>{34, 33, 51, 17, 18, 48, 20, 27, 23, 36, 24});
  CHECK(t->piece(6).turn == -1);
  CHECK(t->piece(7).turn == 1);
}

TEST_CASE("every named layout parses and closes") {
  auto names = layoutNames();
  CHECK(names.size() >= 3);
  CHECK(names.front() == "oval");
  for (const auto& name : names) {
    CAPTURE(name);
    auto t = namedLayout(name);
    REQUIRE(t.ok());
    CHECK(t->size() >= 9);
  }
  auto kidney = namedLayout("kidney");
  int rights = 0;
  for (const Piece& p : kidney->pieces()) rights += p.turn < 0;
  CHECK(rights == 1);
}

TEST_CASE("an unknown token is named with its position") {
  auto e = errorOf("start S L X L S S L L");
  CHECK(contains(e, "unknown piece 'X' at position 4"));
}

TEST_CASE("a piece id must fit the token's type") {
  CHECK(contains(errorOf("start S:17 L L S S L L"),
                 "piece id 17 at position 2 is a curve piece, not a straight"));
  CHECK(contains(errorOf("start S L:36 L S S L L"),
                 "piece id 36 at position 3 is a straight piece, not a curve"));
  CHECK(contains(errorOf("start S:abc L L S S L L"),
                 "piece id 'abc' at position 2 is not a number from 0 to 255"));
  CHECK(contains(errorOf("start:34 S L L S S L L"), "takes no piece id"));
}

TEST_CASE("a layout needs exactly one start") {
  CHECK(contains(errorOf("S S L L S S L L"), "the layout has no start"));
  CHECK(contains(errorOf("start S L L start L L"),
                 "a second start at position 5 (the first is at position 1)"));
}

TEST_CASE("a layout that does not close says by how much") {
  auto e = errorOf("start S L L S L L");
  CHECK(contains(e, "the layout does not close: its end is 560 mm from its start"));
  auto turned = errorOf("start S L");
  CHECK(contains(turned, "heads 90° left of the start direction"));
}

TEST_CASE("an empty layout is an error, comments alone included") {
  CHECK(contains(errorOf(""), "the layout is empty"));
  CHECK(contains(errorOf("  # nothing here\n"), "the layout is empty"));
}

TEST_CASE("loadLayout takes a name or a file, and says when it finds neither") {
  CHECK(loadLayout("oval").ok());
  auto missing = loadLayout("/nonexistent/track.txt");
  REQUIRE_FALSE(missing.ok());
  CHECK(contains(missing.error(), "'/nonexistent/track.txt' is neither a named layout"));
  CHECK_FALSE(contains(missing.error(), "did you mean"));
  auto typo = loadLayout("ovl");
  REQUIRE_FALSE(typo.ok());
  CHECK(contains(typo.error(), "nor a file that exists; did you mean oval?"));

  auto path = std::filesystem::temp_directory_path() / "pitwall_track_test_loop.layout";
  {
    std::ofstream out(path);
    out << "start S S L L S S S L L\n";
  }
  auto t = loadLayout(path.string());
  REQUIRE(t.ok());
  CHECK(t->name() == "pitwall_track_test_loop");
  CHECK(t->size() == 11);

  {
    std::ofstream out(path);
    out << "start S L\n";
  }
  auto bad = loadLayout(path.string());
  REQUIRE_FALSE(bad.ok());
  CHECK(contains(bad.error(), path.string() + ": the layout does not close"));
  std::filesystem::remove(path);
}

TEST_CASE("an unknown piece id is refused with the ids that fit") {
  CHECK(contains(errorOf("start S:200 L L S S L L"),
                 "piece id 200 at position 2 is not a known piece; straight ids are 36, 39, 40, "
                 "48, 51"));
}

TEST_CASE("layoutText: every layout reads back to the same pieces (what a record keeps)") {
  for (const auto& name : layoutNames()) {
    CAPTURE(name);
    auto track = namedLayout(name).value();
    auto again = parseLayout(layoutText(track), "again");
    REQUIRE(again);
    REQUIRE(again->size() == track.size());
    for (std::size_t i = 0; i < track.size(); ++i) {
      CHECK(again->pieces()[i].id == track.pieces()[i].id);
      CHECK(again->pieces()[i].turn == track.pieces()[i].turn);
    }
  }
  CHECK(layoutText(namedLayout("kidney").value()).starts_with("start S:36 L:17"));
}
