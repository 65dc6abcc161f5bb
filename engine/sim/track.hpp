#pragma once
// Track layouts and their geometry, for the simulator (anki-overdrive.md "Track").
//
// Layout text format (docs/simulator.md): whitespace-separated tokens, `#` starts a comment.
//   start            the start pair: piece 34 (340 mm) then piece 33 (220 mm)
//   S | straight     straight, 560 mm
//   L | left         90° curve turning left, centre radius 280 mm
//   R | right        90° curve turning right
// Any token may carry an explicit piece id: `S:39`, `L:18`. A custom piece (docs/tracks.md) has an
// id of its own (0–127, not one of Anki's) and its geometry as keys after commas:
//   S:60,len=300     a straight of 300 mm
//   L:61,r=400,deg=45  a curve of centre radius 400 mm turning 45°
// A layout holds at most one `start` (none: laps are counted from its first piece), must close
// (end where it began, heading the same way), its pieces must not overlap and each must carry a
// code (docs/tracks.md "Rules"); otherwise parsing fails with a sentence naming the piece and
// saying why.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/anki/pieces.hpp"

namespace pitwall::sim {

struct Piece {
  std::uint8_t id = 0;
  anki::PieceType type = anki::PieceType::Straight;
  int turn = 0;  // +1 left curve, −1 right curve, 0 straight
  // A custom piece's geometry; 0 means the stock value of its type.
  double straight_mm = 0;  // a straight's length
  double radius_mm = 0;    // a curve's centre radius
  double angle_deg = 0;    // how far a curve turns

  bool custom() const { return straight_mm > 0 || radius_mm > 0 || angle_deg > 0; }
  double radius() const;  // a curve's centre radius (stock 280 mm); 0 for a straight
  double angle() const;   // a curve's turn in degrees (stock 90); 0 for a straight
  // Length of this piece along a lane at `offset_mm` from the road centre (positive = right in
  // driving direction): a left curve is longer on the right (outer) side.
  double length(double offset_mm) const;
};

// A point on the road and the driving direction there: mm, x to the right and y up, heading in
// degrees counter-clockwise from +x (the frame of docs/view.md).
struct Pose {
  double x = 0, y = 0;
  double heading = 0;
};
// The point `fraction` (0…1) along `piece`, which begins at `start`, `offset_mm` right of its
// centre line, and the heading there (not normalized).
Pose poseOnPiece(const Piece& piece, const Pose& start, double fraction, double offset_mm);

class Track {
 public:
  Track() = default;
  Track(std::string name, std::vector<Piece> pieces);

  const std::string& name() const { return name_; }
  const std::vector<Piece>& pieces() const { return pieces_; }
  std::size_t size() const { return pieces_.size(); }
  const Piece& piece(std::size_t index) const { return pieces_[index % pieces_.size()]; }
  // Index of the first piece after the finish line (piece 33); laps are counted there.
  std::size_t finishIndex() const;
  double lapLength(double offset_mm) const;  // sum of piece lengths along that lane

 private:
  std::string name_;
  std::vector<Piece> pieces_;
};

// The most pieces a layout may have (start counts two): a room's track, with room to spare. It
// bounds the overlap check (every pair of pieces) and what the view and the printer draw.
inline constexpr std::size_t kMaxPieces = 1000;
// The largest layout file loadLayout reads: 1000 pieces and their comments fit many times over.
inline constexpr std::uintmax_t kMaxLayoutFileBytes = 1024 * 1024;

Result<Track, std::string> parseLayout(std::string_view text, std::string name = "custom");
// One token of a layout ("S", "L:17", "S:60,len=300", "start"), checked as parseLayout checks
// it: its pieces (two for start: 34 and 33).
Result<std::vector<Piece>, std::string> parsePiece(std::string_view token);
// The layout text of a track, every piece with its id ("start S:36 L:17 …"): parseLayout reads
// it back to the same pieces (a record keeps the track it was made on this way).
std::string layoutText(const Track& track);
// One piece as a layout token: "S:36", "L:61,r=400,deg=45"; "start" for either start piece.
std::string pieceToken(const Piece& piece);
// Anki's stock pieces with their stock shape, as a layout lays them (docs/tracks.md "Ids"): 34
// and 33 (the start pair), the straights 36, 39, 40, 48, 51 and the curves 17, 18, 20, 23, 24,
// 27 (as left curves; a right one is the same piece laid the other way round).
std::vector<Piece> stockPieces();
// One of them by its id (`track print 40` is S:40, `17` is L:17, `34` the start pair's first
// piece), or a sentence: for an id of Anki's that pitwall has no shape for (10, the
// intersection; 57, 58, 63) and for an id that is no stock piece.
Result<Piece, std::string> stockPiece(int id);
// Named layouts: "oval" (the default: start S L L S S L L, ≈4.0 m), and others listed by
// layoutNames(). loadLayout takes a name or a path to a layout file.
Result<Track, std::string> namedLayout(std::string_view name);
std::vector<std::string> layoutNames();
Result<Track, std::string> loadLayout(std::string_view nameOrPath);

}  // namespace pitwall::sim
