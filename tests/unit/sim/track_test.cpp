#include "engine/sim/track.hpp"

#include <doctest/doctest.h>

#include <algorithm>
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

TEST_CASE("a layout has at most one start; without one its laps begin at its first piece") {
  CHECK(contains(errorOf("start S L L start L L"),
                 "a second start at position 5 (the first is at position 1)"));
  // the okoeth oval (tests/realdata): no start piece
  auto track = parseLayout("R:17 R:18 S:40 R:18 R:23 S:39", "okoeth");
  REQUIRE(track);
  CHECK(track->size() == 6);
  CHECK(track->finishIndex() == 0);
  CHECK(layoutText(*track) == "R:17 R:18 S:40 R:18 R:23 S:39");
}

TEST_CASE("a layout that does not close says by how much") {
  auto e = errorOf("start S L L S L L");
  CHECK(
      contains(e, "the layout does not close: its end (after its last piece, L:23 at position 7)"));
  CHECK(contains(e, ") is 560 mm from its start"));
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

TEST_CASE("a piece id beyond the code's 7 bits, or of another kind, is refused with what fits") {
  CHECK(contains(errorOf("start S:200 L L S S L L"),
                 "piece id 200 at position 2 does not fit the code's 7 bits; a custom piece "
                 "takes an id from 0 to 127 that Anki does not use"));
  CHECK(contains(errorOf("start S:17 L L S S L L"),
                 "piece id 17 at position 2 is a curve piece, not a straight; straight ids are "
                 "36, 39, 40, 48, 51"));
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

TEST_CASE("custom pieces: ids of their own, lengths, radii and angles, read back by layoutText") {
  // Four 45° curves of 400 mm turn the car round; both sides are 1000 mm long.
  const char* text =
      "start S:60,len=440 L:61,r=400,deg=45 L:61,r=400,deg=45 L:61,r=400,deg=45 "
      "L:61,r=400,deg=45 S:60,len=440 S L:61,r=400,deg=45 L:61,r=400,deg=45 "
      "L:61,r=400,deg=45 L:61,r=400,deg=45";
  auto t = parseLayout(text, "custom");
  if (!t) FAIL(t.error());
  REQUIRE(t->size() == 13);
  const Piece& s = t->piece(2);
  const Piece& c = t->piece(3);
  CHECK(s.id == 60);
  CHECK(s.custom());
  CHECK(s.length(0) == doctest::Approx(440));
  CHECK(s.length(50) == doctest::Approx(440));
  CHECK(c.id == 61);
  CHECK(c.radius() == 400);
  CHECK(c.angle() == 45);
  CHECK(c.length(0) == doctest::Approx(400 * std::numbers::pi / 4));
  CHECK(c.length(68) == doctest::Approx((400 + 68) * std::numbers::pi / 4));  // outer in a left
  auto again = parseLayout(layoutText(*t), "again");
  REQUIRE(again);
  CHECK(layoutText(*again) == layoutText(*t));
  CHECK(layoutText(*t).starts_with("start S:60,len=440 L:61,r=400,deg=45"));
  CHECK(again->lapLength(0) == doctest::Approx(t->lapLength(0)));
  // a lone token: one piece, or the start pair
  auto one = parsePiece("L:61,r=400,deg=45");
  REQUIRE(one);
  REQUIRE(one->size() == 1);
  CHECK((*one)[0].radius() == 400);
  auto start = parsePiece("start");
  REQUIRE(start);
  CHECK(start->size() == 2);
  CHECK_FALSE(parsePiece("S L"));
}

TEST_CASE("invalid custom designs are refused with a sentence naming the piece") {
  // does not close: an angle that leaves it turned
  CHECK(contains(errorOf("start S L L S S L L:61,r=280,deg=80"), "does not close"));
  CHECK(contains(errorOf("start S L L S S L L:61,r=280,deg=80"), "heads 10° right of"));
  CHECK(contains(errorOf("start S L L S S L L:61,r=280,deg=80"),
                 "its end (after its last piece, L:61,r=280,deg=80 at position 8) is 49 mm"));
  CHECK(contains(errorOf("start S L L S S L L:61,r=280,deg=80"),
                 "; its curves turn 350° in all, and a closed loop turns 360°"));
  // crosses itself: a full circle after the first straight comes back over it
  CHECK(contains(errorOf("start S L L L L S L L S S S L L"),
                 "pieces S:36 at position 2 and L:23 at position 6 overlap"));
  CHECK(contains(errorOf("start S:60,len=0 L L S S L L"),
                 "'S:60,len=0' at position 2: len '0' is not a positive number of mm"));
  CHECK(contains(errorOf("start S:60,len=1e309 L L S S L L"), "is not a positive number"));
  CHECK(contains(errorOf("start S:60,len=abc L L S S L L"), "is not a positive number"));
  CHECK(contains(errorOf("start S:60,r=300 L L S S L L"),
                 "unknown key 'r'; a straight takes len (mm)"));
  CHECK(contains(errorOf("start S L:61,len=300 L S S L L"),
                 "unknown key 'len'; a curve takes r (centre radius, mm) and deg (angle)"));
  CHECK(contains(errorOf("start S:60,len=100 L L S S L L"),
                 "'S:60,len=100' at position 2 is too short to carry its code: its shortest "
                 "lane is 100 mm and a code section needs 150 mm"));
  CHECK(contains(errorOf("start S:60,len=1400 L L S S L L"),
                 "needs 144 location ids and a 7-bit code carries 128"));
  CHECK(contains(errorOf("start S,len=300 L L S S L L"),
                 "a custom piece needs an id of its own, one Anki does not use, such as "
                 "S:60,len=300"));
  CHECK(
      contains(errorOf("start S:36,len=300 L L S S L L"), "36 is the id of Anki's stock straight"));
  CHECK(contains(errorOf("start L:61,r=400,deg=200 L L S S L L"), "turns more than 180°"));
  CHECK(contains(errorOf("start S:60,len=300 S:60,len=400 L L S S L L"),
                 "'S:60,len=400' at position 3 has id 60, which S:60,len=300 at position 2 has "
                 "with another shape"));
  CHECK(contains(errorOf("start,len=3 S L L S S L L"), "start is always pieces 34 and 33"));
  CHECK(contains(errorOf("start, S L L S S L L"), "start is always pieces 34 and 33"));
  CHECK(contains(errorOf("start S:60,len=560, L L S S L L"),
                 "'S:60,len=560,' at position 2: an empty key (two commas, or one at the end)"));
  CHECK(contains(errorOf("start S:60,,len=560 L L S S L L"), "an empty key"));
  CHECK(contains(errorOf("start S L:61,deg=90,deg=90 L S S L L"),
                 "'L:61,deg=90,deg=90' at position 3: deg is given twice; give each key once"));
  // a hostile token is shown short and escaped: 80 bytes at most, bytes that are not UTF-8 as \xNN
  const std::string huge = "start S:60,len=" + std::string(100000, '9') + "\xff L L S S L L";
  const std::string e = errorOf(huge);
  CHECK(e.size() < 400);
  CHECK(contains(e, "…"));
  CHECK(contains(errorOf("start Q\xff\x1b[2J L L S S L L"), "unknown piece 'Q\\xff\\x1b[2J'"));
  // hostile numbers and text never crash and always say what is wrong
  for (const char* bad : {"S:60,len=-1", "S:60,len=nan", "S:60,len=inf", "S:60,len=", "S:60,=3",
                          "S:60,,", "L:61,r=1e300", "L:61,deg=0.0000001", "S:9999999999999999999",
                          "S:60,len=300,len=300,len=1e9"}) {
    CAPTURE(bad);
    auto r = parseLayout(std::string("start ") + bad + " L L S S L L");
    CHECK_FALSE(r.ok());
    if (!r.ok()) CHECK_FALSE(r.error().empty());
  }
}

// An oval with `k` straights along the top beside the start and k + 1 along the bottom: 2k + 7
// pieces.
std::string longOval(int k) {
  std::string text = "start";
  for (int i = 0; i < k; ++i) text += " S";
  text += " L L";
  for (int i = 0; i <= k; ++i) text += " S";
  return text + " L L";
}

TEST_CASE("a layout of more than 1000 pieces is refused with a sentence that counts them") {
  auto big = parseLayout(longOval(496));  // 999 pieces: within the cap, and it closes
  REQUIRE(big.ok());
  CHECK(big->size() == 999);
  CHECK(errorOf(longOval(497)) ==
        "a layout of 1001 pieces is more than the 1000 pieces pitwall lays out (a room-sized "
        "track has a few dozen); split it into smaller layouts");
  // a hostile length is counted past the cap, not parsed: 10⁶ more tokens, comments between
  std::string huge = "start";
  for (int i = 0; i < 1'000'000; ++i) huge += i % 1000 == 0 ? " S:36 # a comment\n" : " S:36";
  CHECK(contains(errorOf(huge), "a layout of 1000002 pieces is more than the 1000 pieces"));
}

TEST_CASE("a layout file larger than 1 MB is refused unread") {
  const auto path = std::filesystem::temp_directory_path() / "pitwall_track_test_big.layout";
  {
    std::ofstream out(path);
    out << longOval(1) << "\n" << std::string(kMaxLayoutFileBytes, '#') << "\n";
  }
  auto r = loadLayout(path.string());
  std::filesystem::remove(path);
  REQUIRE_FALSE(r.ok());
  CHECK(contains(r.error(), " is 1048597 bytes, more than the 1048576 a layout file may be"));
}

TEST_CASE("stock pieces by id: the start pair, straights and curves with their stock shape") {
  const auto stock = stockPieces();
  REQUIRE(stock.size() == 13);
  for (const Piece& p : stock) {
    CAPTURE(int(p.id));
    CHECK(anki::pieceType(p.id) == p.type);
    CHECK_FALSE(p.custom());
    auto same = stockPiece(p.id);
    REQUIRE(same.ok());
    CHECK(same->id == p.id);
    // what a layout token makes of it: the same piece
    auto parsed = parsePiece(pieceToken(p));
    REQUIRE(parsed.ok());
    CHECK(std::count_if(parsed->begin(), parsed->end(), [&](const Piece& q) {
            return q.id == p.id && q.type == p.type && q.turn == p.turn;
          }) == 1);
  }
  CHECK(stockPiece(40)->type == anki::PieceType::Straight);
  CHECK(stockPiece(40)->length(0) == 560);
  CHECK(stockPiece(17)->turn == 1);
  CHECK(stockPiece(17)->angle() == 90);
  CHECK(stockPiece(34)->type == anki::PieceType::StartLong);
  CHECK(stockPiece(33)->type == anki::PieceType::StartShort);
  // Anki's pieces without a shape here, and ids that are no stock piece: a sentence
  CHECK(
      stockPiece(10).error().starts_with("piece 10 is Anki's intersection, which pitwall has "
                                         "no shape for"));
  CHECK(stockPiece(58).error().find("jump-ramp") != std::string::npos);
  CHECK(stockPiece(60).error().starts_with("60 is not one of Anki's stock pieces"));
  CHECK(contains(stockPiece(60).error(), "such as S:60,len=300 or L:60,r=400,deg=45"));
  CHECK(contains(stockPiece(300).error(), "such as S:60,len=300"));
  CHECK(contains(stockPiece(-1).error(), "-1 is not one of Anki's stock pieces"));
}
