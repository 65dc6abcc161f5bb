#include "engine/sim/track.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace pitwall::sim {

namespace {

// A failed parse: one sentence saying what is wrong and what to do.
Unexpected<std::string> fail(std::string why) {
  return {std::move(why)};
}

// Default piece ids when a token carries none: the ids of a starter kit, in turn
// (anki-overdrive.md "Track").
constexpr std::array<std::uint8_t, 5> kStraightIds{36, 39, 40, 48, 51};
constexpr std::array<std::uint8_t, 6> kCurveIds{17, 18, 20, 23, 24, 27};

// How far a layout's end may lie from its start and still count as closed: pieces fit with play.
constexpr double kClosureToleranceMm = 1.0;

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

template <std::size_t N>
std::string idList(const std::array<std::uint8_t, N>& ids) {
  std::string out;
  for (std::uint8_t id : ids) out += (out.empty() ? "" : ", ") + std::to_string(id);
  return out;
}

std::string formatMm(double mm) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", std::abs(mm) < 0.5 ? 0.0 : mm);  // never "-0"
  return buf;
}

// Position and heading (quarter turns counter-clockwise from the start direction) while walking
// the centre line; headings stay integers so a closed layout closes exactly.
struct Walk {
  double x = 0, y = 0;
  int quarter = 0;
  void advance(const Piece& p) {
    static constexpr int kDx[4] = {1, 0, -1, 0};
    static constexpr int kDy[4] = {0, 1, 0, -1};
    int h = ((quarter % 4) + 4) % 4;
    if (p.turn == 0) {
      double len = p.length(0);
      x += kDx[h] * len;
      y += kDy[h] * len;
      return;
    }
    // A 90° arc moves the car one radius forward and one radius sideways (to the turn side).
    int side = ((h + p.turn) % 4 + 4) % 4;
    x += (kDx[h] + kDx[side]) * anki::kCurveRadiusMm;
    y += (kDy[h] + kDy[side]) * anki::kCurveRadiusMm;
    quarter += p.turn;
  }
};

}  // namespace

double Piece::length(double offset_mm) const {
  switch (type) {
    case anki::PieceType::StartLong:
      return anki::kStartLongLengthMm;
    case anki::PieceType::StartShort:
      return anki::kStartShortLengthMm;
    case anki::PieceType::Curve:
      // A left curve (turn +1) has its centre on the left, so lanes to the right (+) are outer.
      return (anki::kCurveRadiusMm + turn * offset_mm) * std::numbers::pi / 2;
    default:
      return anki::kStraightLengthMm;
  }
}

Track::Track(std::string name, std::vector<Piece> pieces)
    : name_(std::move(name)), pieces_(std::move(pieces)) {}

std::size_t Track::finishIndex() const {
  for (std::size_t i = 0; i < pieces_.size(); ++i)
    if (pieces_[i].type == anki::PieceType::StartShort) return i;
  return 0;
}

std::string layoutText(const Track& track) {
  std::string out;
  const auto& pieces = track.pieces();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    if (p.type == anki::PieceType::StartLong && i + 1 < pieces.size() &&
        pieces[i + 1].type == anki::PieceType::StartShort) {
      out += out.empty() ? "start" : " start";
      ++i;  // the pair is one token
      continue;
    }
    const char* kind = p.turn > 0 ? "L" : p.turn < 0 ? "R" : "S";
    out += (out.empty() ? "" : " ") + std::string(kind) + ":" + std::to_string(p.id);
  }
  return out;
}

double Track::lapLength(double offset_mm) const {
  double sum = 0;
  for (const Piece& p : pieces_) sum += p.length(offset_mm);
  return sum;
}

Result<Track, std::string> parseLayout(std::string_view text, std::string name) {
  std::vector<Piece> pieces;
  std::size_t straights = 0, curves = 0;
  int position = 0;
  int startAt = 0;
  std::size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (c == '#') {  // comment to the end of the line
      while (i < text.size() && text[i] != '\n') ++i;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])) &&
           text[end] != '#')
      ++end;
    std::string_view token = text.substr(i, end - i);
    i = end;
    ++position;
    std::string at = " at position " + std::to_string(position);

    std::string_view kind = token;
    std::string_view idText;
    bool hasId = false;
    if (auto colon = token.find(':'); colon != std::string_view::npos) {
      kind = token.substr(0, colon);
      idText = token.substr(colon + 1);
      hasId = true;
    }
    std::string k = lower(kind);

    if (k == "start") {
      if (hasId)
        return fail("'" + std::string(token) + "'" + at +
                    ": start is always pieces 34 and 33 and takes no piece id");
      if (startAt != 0)
        return fail("a second start" + at + " (the first is at position " +
                    std::to_string(startAt) + "); a track has exactly one start");
      startAt = position;
      pieces.push_back({anki::kFinishBefore, anki::PieceType::StartLong, 0});
      pieces.push_back({anki::kFinishAfter, anki::PieceType::StartShort, 0});
      continue;
    }

    int turn = 0;
    anki::PieceType type = anki::PieceType::Straight;
    if (k == "s" || k == "straight") {
      type = anki::PieceType::Straight;
    } else if (k == "l" || k == "left") {
      type = anki::PieceType::Curve;
      turn = 1;
    } else if (k == "r" || k == "right") {
      type = anki::PieceType::Curve;
      turn = -1;
    } else {
      return fail("unknown piece '" + std::string(token) + "'" + at +
                  "; use start, S (straight), L (left) or R (right), optionally with "
                  ":ID such as S:39");
    }

    std::uint8_t id = 0;
    if (hasId) {
      unsigned value = 0;
      auto [ptr, ec] = std::from_chars(idText.data(), idText.data() + idText.size(), value);
      if (idText.empty() || ec != std::errc() || ptr != idText.data() + idText.size() ||
          value > 255)
        return fail("piece id '" + std::string(idText) + "'" + at +
                    " is not a number from 0 to 255");
      id = static_cast<std::uint8_t>(value);
      anki::PieceType actual = anki::pieceType(id);
      if (actual != type) {
        std::string want(anki::pieceTypeName(type));
        std::string what =
            actual == anki::PieceType::Unknown
                ? " is not a known piece"
                : " is a " + std::string(anki::pieceTypeName(actual)) + " piece, not a " + want;
        return fail("piece id " + std::to_string(value) + at + what + "; " + want + " ids are " +
                    (type == anki::PieceType::Straight ? idList(kStraightIds) : idList(kCurveIds)));
      }
    } else if (type == anki::PieceType::Straight) {
      id = kStraightIds[straights++ % kStraightIds.size()];
    } else {
      id = kCurveIds[curves++ % kCurveIds.size()];
    }
    pieces.push_back({id, type, turn});
  }

  if (pieces.empty())
    return fail(
        std::string("the layout is empty; list its pieces, for example `start S L L S S L L`"));
  if (startAt == 0)
    return fail(std::string(
        "the layout has no start; add `start` (pieces 34 and 33) where the finish line is"));

  Walk walk;
  for (const Piece& p : pieces) walk.advance(p);
  double gap = std::hypot(walk.x, walk.y);
  int heading = ((walk.quarter % 4) + 4) % 4;
  if (gap > kClosureToleranceMm || heading != 0) {
    std::string why = "the layout does not close: its end is " + formatMm(gap) +
                      " mm from its start (x " + formatMm(walk.x) + " mm, y " + formatMm(walk.y) +
                      " mm)";
    if (heading != 0)
      why += " and heads " + std::to_string(heading == 2 ? 180 : 90) + "° " +
             (heading == 1   ? "left of"
              : heading == 3 ? "right of"
                             : "away from") +
             " the start direction";
    return fail(why + "; add or remove pieces until it does");
  }
  return Track(std::move(name), std::move(pieces));
}

}  // namespace pitwall::sim
