#pragma once
// Track layouts and their geometry, for the simulator (anki-overdrive.md "Track").
//
// Layout text format (docs/simulator.md): whitespace-separated tokens, `#` starts a comment.
//   start            the start pair: piece 34 (340 mm) then piece 33 (220 mm)
//   S | straight     straight, 560 mm
//   L | left         90° curve turning left, centre radius 280 mm
//   R | right        90° curve turning right
// Any token may carry an explicit piece id: `S:39`, `L:18`. A layout must contain exactly one
// `start` and must close (end where it began, heading the same way); otherwise parsing fails with
// a sentence saying why.
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
  // Length of this piece along a lane at `offset_mm` from the road centre (positive = right in
  // driving direction): a left curve is longer on the right (outer) side.
  double length(double offset_mm) const;
};

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

Result<Track, std::string> parseLayout(std::string_view text, std::string name = "custom");
// The layout text of a track, every piece with its id ("start S:36 L:17 …"): parseLayout reads
// it back to the same pieces (a record keeps the track it was made on this way).
std::string layoutText(const Track& track);
// Named layouts: "oval" (the default: start S L L S S L L, ≈4.0 m), and others listed by
// layoutNames(). loadLayout takes a name or a path to a layout file.
Result<Track, std::string> namedLayout(std::string_view name);
std::vector<std::string> layoutNames();
Result<Track, std::string> loadLayout(std::string_view nameOrPath);

}  // namespace pitwall::sim
