#include "engine/sim/track.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "engine/core/printable.hpp"
#include "engine/sim/code_layout.hpp"
#include "engine/sim/footprint.hpp"

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
constexpr double kClosureToleranceDeg = 0.01;
// Beyond these a custom piece is a mistake (a typo's extra zero), not a piece anyone prints.
constexpr double kMaxRadiusMm = 5000;
constexpr double kMaxStraightMm = 5000;

// Text of the layout in an error: at most 80 bytes, control characters and bytes that are not
// UTF-8 escaped (a file may hold anything).
std::string shown(std::string_view s) {
  return printable(s, 80);
}

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

// The shortest text that reads back as exactly `v` (a layout written back must close as it did).
std::string formatNumber(double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::string("nan");
}

// Position and heading while walking the centre line.
struct Walk {
  Pose at;
  void advance(const Piece& p) { at = poseOnPiece(p, at, 1.0, 0); }
};

// The heading's difference from the start direction, in (−180, 180].
double headingError(double heading) {
  double d = std::fmod(heading, 360.0);
  if (d > 180) d -= 360;
  if (d <= -180) d += 360;
  return d;
}

}  // namespace

Pose poseOnPiece(const Piece& p, const Pose& start, double fraction, double offset_mm) {
  const double h = start.heading * std::numbers::pi / 180;
  const double dx = std::cos(h), dy = std::sin(h);
  const double rx = dy, ry = -dx;  // right of the driving direction
  if (p.turn == 0) {
    const double len = p.length(0) * fraction;
    return {start.x + dx * len + rx * offset_mm, start.y + dy * len + ry * offset_mm,
            start.heading};
  }
  // The arc's centre lies one radius to the turn's side; a lane right of the centre line is
  // outer in a left curve (turn +1) and inner in a right one.
  const double R = p.radius(), t = p.turn;
  const double cx = start.x - t * rx * R, cy = start.y - t * ry * R;
  const double turned = t * fraction * p.angle();
  const double phi = turned * std::numbers::pi / 180;
  // From the centre to the start point, scaled to the lane's radius, turned by phi.
  const double r = R + t * offset_mm;
  const double ux = (start.x - cx) / R, uy = (start.y - cy) / R;
  const double c = std::cos(phi), s = std::sin(phi);
  return {cx + r * (ux * c - uy * s), cy + r * (ux * s + uy * c), start.heading + turned};
}

double Piece::radius() const {
  if (turn == 0) return 0;
  return radius_mm > 0 ? radius_mm : anki::kCurveRadiusMm;
}

double Piece::angle() const {
  if (turn == 0) return 0;
  return angle_deg > 0 ? angle_deg : 90;
}

double Piece::length(double offset_mm) const {
  if (turn != 0)  // a left curve (turn +1) has its centre on the left: lanes right (+) are outer
    return (radius() + turn * offset_mm) * angle() * std::numbers::pi / 180;
  switch (type) {
    case anki::PieceType::StartLong:
      return anki::kStartLongLengthMm;
    case anki::PieceType::StartShort:
      return anki::kStartShortLengthMm;
    default:
      return straight_mm > 0 ? straight_mm : anki::kStraightLengthMm;
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
    out += (out.empty() ? "" : " ") + pieceToken(p);
  }
  return out;
}

std::string pieceToken(const Piece& p) {
  if (p.type == anki::PieceType::StartLong || p.type == anki::PieceType::StartShort)
    return "start";  // the pair is one token
  std::string out = p.turn > 0 ? "L" : p.turn < 0 ? "R" : "S";
  out += ":" + std::to_string(p.id);
  if (p.straight_mm > 0) out += ",len=" + formatNumber(p.straight_mm);
  if (p.radius_mm > 0) out += ",r=" + formatNumber(p.radius_mm);
  if (p.angle_deg > 0) out += ",deg=" + formatNumber(p.angle_deg);
  return out;
}

std::vector<Piece> stockPieces() {
  std::vector<Piece> out{{anki::kFinishBefore, anki::PieceType::StartLong, 0},
                         {anki::kFinishAfter, anki::PieceType::StartShort, 0}};
  for (std::uint8_t id : kStraightIds) out.push_back({id, anki::PieceType::Straight, 0});
  for (std::uint8_t id : kCurveIds) out.push_back({id, anki::PieceType::Curve, 1});
  return out;
}

Result<Piece, std::string> stockPiece(int id) {
  for (const Piece& p : stockPieces())
    if (p.id == id) return p;
  const std::string number = std::to_string(id);
  if (id >= 0 && id <= 255 &&
      anki::pieceType(static_cast<std::uint8_t>(id)) != anki::PieceType::Unknown)
    return fail("piece " + number + " is Anki's " +
                std::string(anki::pieceTypeName(anki::pieceType(static_cast<std::uint8_t>(id)))) +
                ", which pitwall has no shape for: it lays out, draws and prints the start pair "
                "(34, 33), straights (" +
                idList(kStraightIds) + ") and curves (" + idList(kCurveIds) + ")");
  // A custom piece is a shape with an id of its own: suggest this id when the code can carry it.
  const std::string own = id >= 0 && id <= int(anki::optical::kMaxId) ? number : "60";
  return fail(number +
              " is not one of Anki's stock pieces: they are the start pair (34, 33), "
              "straights (" +
              idList(kStraightIds) + ") and curves (" + idList(kCurveIds) +
              "); a piece of your own needs its shape, such as S:" + own + ",len=300 or L:" + own +
              ",r=400,deg=45");
}

double Track::lapLength(double offset_mm) const {
  double sum = 0;
  for (const Piece& p : pieces_) sum += p.length(offset_mm);
  return sum;
}

namespace {

// The pieces of a layout text, each checked on its own (kind, id, keys, code), before the checks
// of the whole (one start, closed, no overlap).
struct Parsed {
  std::vector<Piece> pieces;
  std::vector<int> positions;  // of each piece's token, for errors
  int tokens = 0;
  int startAt = 0;
};

// A layout past kMaxPieces: the sentence counts its pieces (the rest only lexed, never parsed:
// each token one piece, start two), so checking it stays linear however long the text is.
std::string tooManyPieces(std::size_t before, std::string_view token, std::string_view rest) {
  std::size_t count = before + (lower(token) == "start" ? 2 : 1);
  for (std::size_t i = 0; i < rest.size();) {
    if (rest[i] == '#') {
      while (i < rest.size() && rest[i] != '\n') ++i;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(rest[i]))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < rest.size() && !std::isspace(static_cast<unsigned char>(rest[end])) &&
           rest[end] != '#')
      ++end;
    count += lower(rest.substr(i, end - i)) == "start" ? 2 : 1;
    i = end;
  }
  return "a layout of " + std::to_string(count) + " pieces is more than the " +
         std::to_string(kMaxPieces) +
         " pieces pitwall lays out (a room-sized track has a few dozen); split "
         "it into smaller layouts";
}

Result<Parsed, std::string> parseTokens(std::string_view text) {
  Parsed parsed;
  auto& pieces = parsed.pieces;
  auto& positions = parsed.positions;
  auto& startAt = parsed.startAt;
  std::size_t straights = 0, curves = 0;
  int& position = parsed.tokens;
  std::array<int, 256> firstWithId;  // the index of the first piece with each id, or −1
  firstWithId.fill(-1);
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
    if (pieces.size() + (lower(token) == "start" ? 2 : 1) > kMaxPieces)
      return fail(tooManyPieces(pieces.size(), token, text.substr(i)));
    std::string at = " at position " + std::to_string(position);

    std::string_view head = token, keys;
    const auto comma = token.find(',');
    const bool hasKeys = comma != std::string_view::npos;
    if (hasKeys) {
      head = token.substr(0, comma);
      keys = token.substr(comma + 1);
    }
    std::string_view kind = head;
    std::string_view idText;
    bool hasId = false;
    if (auto colon = head.find(':'); colon != std::string_view::npos) {
      kind = head.substr(0, colon);
      idText = head.substr(colon + 1);
      hasId = true;
    }
    std::string k = lower(kind);
    const std::string named = "'" + shown(token) + "'" + at;

    if (k == "start") {
      if (hasId || hasKeys)
        return fail(named + ": start is always pieces 34 and 33 and takes no piece id or keys");
      if (startAt != 0)
        return fail("a second start" + at + " (the first is at position " +
                    std::to_string(startAt) + "); a track has at most one start");
      startAt = position;
      pieces.push_back({anki::kFinishBefore, anki::PieceType::StartLong, 0});
      pieces.push_back({anki::kFinishAfter, anki::PieceType::StartShort, 0});
      positions.push_back(position);
      positions.push_back(position);
      continue;
    }

    Piece piece;
    if (k == "s" || k == "straight") {
      piece.type = anki::PieceType::Straight;
    } else if (k == "l" || k == "left") {
      piece.type = anki::PieceType::Curve;
      piece.turn = 1;
    } else if (k == "r" || k == "right") {
      piece.type = anki::PieceType::Curve;
      piece.turn = -1;
    } else {
      return fail("unknown piece '" + shown(token) + "'" + at +
                  "; use start, S (straight), L (left) or R (right), optionally with "
                  ":ID such as S:39");
    }
    const anki::PieceType type = piece.type;

    // Keys: a custom piece's geometry (len for a straight, r and deg for a curve).
    std::vector<const double*> given;
    for (bool more = hasKeys; more;) {
      const auto next = keys.find(',');
      std::string_view kv = keys.substr(0, next);
      more = next != std::string_view::npos;
      if (more) keys = keys.substr(next + 1);
      if (kv.empty())
        return fail(named + ": an empty key (two commas, or one at the end); write keys as " +
                    (piece.turn ? "L:61,r=400,deg=45" : "S:60,len=300"));
      auto eq = kv.find('=');
      std::string key = lower(kv.substr(0, eq));
      const char* allowed = piece.turn ? "r (centre radius, mm) and deg (angle)" : "len (mm)";
      double* slot = piece.turn == 0 && key == "len"   ? &piece.straight_mm
                     : piece.turn != 0 && key == "r"   ? &piece.radius_mm
                     : piece.turn != 0 && key == "deg" ? &piece.angle_deg
                                                       : nullptr;
      if (!slot)
        return fail(named + ": unknown key '" + shown(kv.substr(0, eq)) + "'; a " +
                    (piece.turn ? "curve" : "straight") + " takes " + allowed + ", such as " +
                    (piece.turn ? "L:61,r=400,deg=45" : "S:60,len=300"));
      std::string_view valueText = eq == std::string_view::npos ? "" : kv.substr(eq + 1);
      double value = 0;
      auto [ptr, ec] =
          std::from_chars(valueText.data(), valueText.data() + valueText.size(), value);
      if (valueText.empty() || ec != std::errc() || ptr != valueText.data() + valueText.size() ||
          !std::isfinite(value) || value <= 0)
        return fail(named + ": " + shown(key) + " '" + shown(valueText) +
                    "' is not a positive number" + (key == "deg" ? " of degrees" : " of mm"));
      if (key == "deg" && value > 180)
        return fail(named + ": deg=" + formatNumber(value) +
                    " turns more than 180°; split it into two curves");
      if (key == "r" && value > kMaxRadiusMm)
        return fail(named + ": r=" + formatNumber(value) + " mm is more than " +
                    formatNumber(kMaxRadiusMm) + " mm; use a straight");
      if (key == "len" && value > kMaxStraightMm)
        return fail(named + ": len=" + formatNumber(value) + " mm is more than " +
                    formatNumber(kMaxStraightMm) + " mm; split it into two straights");
      if (std::find(given.begin(), given.end(), slot) != given.end())
        return fail(named + ": " + key + " is given twice; give each key once");
      given.push_back(slot);
      *slot = value;
    }

    if (hasId) {
      unsigned value = 0;
      auto [ptr, ec] = std::from_chars(idText.data(), idText.data() + idText.size(), value);
      if (idText.empty() || ec != std::errc() || ptr != idText.data() + idText.size() ||
          value > 255)
        return fail("piece id '" + shown(idText) + "'" + at + " is not a number from 0 to 255");
      piece.id = static_cast<std::uint8_t>(value);
      anki::PieceType actual = anki::pieceType(piece.id);
      if (actual == anki::PieceType::Unknown) {
        // A custom piece: an id of its own, which its code must be able to carry.
        if (value > anki::optical::kMaxId)
          return fail("piece id " + std::to_string(value) + at +
                      " does not fit the code's 7 bits; a custom piece takes an id from 0 to " +
                      std::to_string(anki::optical::kMaxId) + " that Anki does not use");
      } else if (actual != type) {
        std::string want(anki::pieceTypeName(type));
        return fail("piece id " + std::to_string(value) + at + " is a " +
                    std::string(anki::pieceTypeName(actual)) + " piece, not a " + want + "; " +
                    want + " ids are " +
                    (type == anki::PieceType::Straight ? idList(kStraightIds) : idList(kCurveIds)) +
                    ", and a custom piece takes an id Anki does not use");
      } else if (piece.custom()) {
        return fail(named + ": " + std::to_string(value) + " is the id of Anki's stock " +
                    std::string(anki::pieceTypeName(type)) +
                    "; a piece of another shape needs an id of its own, one Anki does not use "
                    "(such as 60)");
      }
    } else if (piece.custom()) {
      return fail(named +
                  ": a custom piece needs an id of its own, one Anki does not use, "
                  "such as " +
                  std::string(piece.turn ? "L:61," : "S:60,") +
                  shown(token.substr(token.find(',') + 1)));
    } else if (type == anki::PieceType::Straight) {
      piece.id = kStraightIds[straights++ % kStraightIds.size()];
    } else {
      piece.id = kCurveIds[curves++ % kCurveIds.size()];
    }

    // One custom id, one shape: the scan lap and pitwall.piece learn a piece's shape by its id.
    if (const int j = firstWithId[piece.id]; j >= 0) {
      const Piece& o = pieces[static_cast<std::size_t>(j)];
      if ((o.turn == 0) != (piece.turn == 0) || o.length(0) != piece.length(0) ||
          o.angle() != piece.angle())
        return fail(named + " has id " + std::to_string(piece.id) + ", which " + pieceToken(o) +
                    " at position " + std::to_string(positions[static_cast<std::size_t>(j)]) +
                    " has with another shape; one id, one shape: give it an id of its own");
    }

    // Its code must fit: a section on its shortest lane, and location ids within 7 bits.
    CodeLayout code = codeLayout(piece);
    double shortest = code.rows.front().length_mm, longest = shortest;
    for (const CodeRow& row : code.rows) {
      shortest = std::min(shortest, row.length_mm);
      longest = std::max(longest, row.length_mm);
    }
    const double sectionMm = CodeGeometry{}.section_min_mm;
    if (shortest < sectionMm)
      return fail(named + " is too short to carry its code: its shortest lane is " +
                  formatMm(shortest) + " mm and a code section needs " + formatMm(sectionMm) +
                  " mm; make it " + (piece.turn ? "wider (r) or turn further (deg)" : "longer"));
    if (code.locations > anki::optical::kMaxId + 1)
      return fail(named + " needs " + std::to_string(code.locations) +
                  " location ids and a 7-bit code carries 128; make it shorter or split it "
                  "into two pieces");
    if (firstWithId[piece.id] < 0) firstWithId[piece.id] = static_cast<int>(pieces.size());
    pieces.push_back(piece);
    positions.push_back(position);
  }
  return parsed;
}

}  // namespace

Result<std::vector<Piece>, std::string> parsePiece(std::string_view token) {
  auto parsed = parseTokens(token);
  if (!parsed) return Unexpected<std::string>(parsed.error());
  if (parsed->tokens != 1)
    return fail("'" + shown(token) + "' is " + std::to_string(parsed->tokens) +
                " pieces; give one, such as S, L:17, start or S:60,len=300");
  return std::move(parsed->pieces);
}

Result<Track, std::string> parseLayout(std::string_view text, std::string name) {
  auto parsed = parseTokens(text);
  if (!parsed) return Unexpected<std::string>(parsed.error());
  auto& pieces = parsed->pieces;
  const auto& positions = parsed->positions;
  const int startAt = parsed->startAt;
  if (pieces.empty())
    return fail(
        std::string("the layout is empty; list its pieces, for example `start S L L S S L L`"));
  // No start is a track without the start/finish piece (real tracks need not have one): its
  // laps are counted at the beginning of its first piece (Track::finishIndex).

  Walk walk;
  for (const Piece& p : pieces) walk.advance(p);
  double gap = std::hypot(walk.at.x, walk.at.y);
  double turned = headingError(walk.at.heading);
  if (gap > kClosureToleranceMm || std::abs(turned) > kClosureToleranceDeg) {
    std::string why =
        "the layout does not close: its end (after its last piece, " + pieceToken(pieces.back()) +
        " at position " + std::to_string(positions.back()) + ") is " + formatMm(gap) +
        " mm from its start (x " + formatMm(walk.at.x) + " mm, y " + formatMm(walk.at.y) + " mm)";
    if (std::abs(turned) > kClosureToleranceDeg)
      why += " and heads " + formatNumber(std::round(std::abs(turned) * 100) / 100) + "° " +
             (std::abs(turned) > 179.99 ? "away from"
              : turned > 0              ? "left of"
                                        : "right of") +
             " the start direction";
    // How far the curves turn in all: a closed loop turns 360°, so a curve of the wrong angle
    // or direction shows here.
    double curves = 0;
    for (const Piece& p : pieces) curves += p.turn * p.angle();
    if (std::abs(turned) > kClosureToleranceDeg)
      why += "; its curves turn " + formatNumber(std::round(curves * 100) / 100) +
             "° in all, and a closed loop turns 360° (or −360° turning right)";
    return fail(why + "; add or remove pieces until it does");
  }
  if (auto overlap = firstOverlap(pieces)) {
    auto [a, b] = *overlap;
    return fail("pieces " + pieceToken(pieces[a]) + " at position " + std::to_string(positions[a]) +
                " and " + pieceToken(pieces[b]) + " at position " + std::to_string(positions[b]) +
                " overlap; a layout may not cross itself: change the pieces between them");
  }
  return Track(std::move(name), std::move(pieces));
}

}  // namespace pitwall::sim
