// Track layout text (engine/sim/track.hpp, docs/tracks.md): what a user writes in a track file,
// any bytes. Never a crash or an exception; a refusal is a sentence. An accepted layout keeps
// every promise the simulator and the printer rely on:
// - it has one start pair, closes within 1 mm and 0.01°, and its pieces do not overlap (checked
//   again here by walking it);
// - every piece's code fits: a section on every row, at most 128 location ids, ids of 7 bits;
// - layoutText writes it back to text that reads as the same pieces, and each of its tokens
//   reads alone (parsePiece) as the same piece.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "engine/sim/code_layout.hpp"
#include "engine/sim/footprint.hpp"
#include "engine/sim/track.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {

bool samePiece(const sim::Piece& a, const sim::Piece& b) {
  return a.id == b.id && a.type == b.type && a.turn == b.turn &&
         std::abs(a.length(0) - b.length(0)) < 1e-6 && std::abs(a.angle() - b.angle()) < 1e-9;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto track = sim::parseLayout(text);
  if (!track) {
    FUZZ_CHECK(!track.error().empty(), text);
    return 0;
  }
  const auto& pieces = track->pieces();
  int starts = 0;
  sim::Pose at;
  for (const sim::Piece& p : pieces) {
    if (p.type == anki::PieceType::StartLong) ++starts;
    FUZZ_CHECK(p.id <= anki::optical::kMaxId, text);
    auto code = sim::codeLayout(p);
    FUZZ_CHECK(code.locations <= anki::optical::kMaxId + 1, text);
    for (const auto& row : code.rows) FUZZ_CHECK(row.sections >= 1, text);
    at = sim::poseOnPiece(p, at, 1.0, 0);
  }
  // at most one start; none is a track without the start piece (laps from its first piece)
  FUZZ_CHECK(starts <= 1, text);
  FUZZ_CHECK(track->finishIndex() < pieces.size(), text);
  FUZZ_CHECK(std::hypot(at.x, at.y) <= 1.0 + 1e-9, text);
  double turned = std::remainder(at.heading, 360.0);
  FUZZ_CHECK(std::abs(turned) <= 0.01 + 1e-9, text);
  FUZZ_CHECK(!sim::firstOverlap(pieces), text);

  const std::string written = sim::layoutText(*track);
  auto again = sim::parseLayout(written);
  FUZZ_CHECK(again.ok(), text + " → " + written + ": " + (again ? "" : again.error()));
  FUZZ_CHECK(again->size() == pieces.size(), text + " → " + written);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    FUZZ_CHECK(samePiece(again->pieces()[i], pieces[i]), text + " → " + written);
    if (pieces[i].type == anki::PieceType::StartShort) continue;  // read with its 34
    auto alone = sim::parsePiece(sim::pieceToken(pieces[i]));
    FUZZ_CHECK(alone.ok(), sim::pieceToken(pieces[i]));
    FUZZ_CHECK(samePiece(alone->front(), pieces[i]), sim::pieceToken(pieces[i]));
  }
  return 0;
}
