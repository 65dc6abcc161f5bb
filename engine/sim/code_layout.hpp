#pragma once
// Where a piece's optical code lies (docs/tracks.md "The code"): 16 rows (lane lines) across the
// road, each cut into sections of 9 strokes (engine/protocol/anki/optical_code.hpp) that carry
// the piece id and one location id. A row holds as many sections as fit whole at
// `section_min_mm` each; location ids count the sections row by row, from the leftmost row (in
// the piece's forward direction) to the right, and along each row forward. With the defaults this
// gives what real pieces report (anki-overdrive.md "Track"): straights 0–47, curves 0–37,
// piece 33 0–15, piece 34 0–31. The simulator reports these ids, `track print` draws them and
// `track verify` reads them back.
#include <array>
#include <optional>
#include <vector>

#include "engine/protocol/anki/optical_code.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::sim {

// The dimensions of the code, in mm. Which of them are measured and which guessed, and where
// each comes from: docs/tracks.md "Dimensions". A user with a real car calibrates them there.
struct CodeGeometry {
  int rows = 16;                  // lane lines across a piece (seed 000 §4.3.6)
  double row_pitch_mm = 12;       // between lane lines: 16 rows across the ±96 mm road
  double section_min_mm = 150;    // a section's length along its row, at least
  double stroke_pitch_mm = 16.5;  // between the strokes of a section, along the row
  double stroke_length_mm = 9.9;  // a stroke's length along the row
  double line_width_mm = 1.31;    // the lane line the car follows
  double gap_mm = 0.78;           // from the line's edge to a stroke's inner edge
  double thin_mm = 0.52;          // a 0, and the piece side of a boundary
  double thick_mm = 1.31;         // a 1
  double wide_mm = 2.09;          // the location side of a boundary

  double width(anki::optical::Width w) const;
  // Where a stroke of width `w` lies across its row: its inner edge and outer edge, mm from
  // the line's centre (the same on both sides).
  double innerEdge() const { return line_width_mm / 2 + gap_mm; }
};

struct CodeRow {
  double offset_mm = 0;  // the lane line, right of the centre line (piece's forward direction)
  double length_mm = 0;  // along that line
  int sections = 0;
  int first_location = 0;  // the lowest location id of the row
  // The row's ids run against the layout's direction: a right curve is a left curve's piece
  // driven backwards (see codeLayout).
  bool reversed = false;
  // The location id of section k, counted in the layout's driving direction.
  int locationOf(int k) const { return first_location + (reversed ? sections - 1 - k : k); }
  // The centre of section k along the row (mm from its start) and of its strokes.
  double sectionCentre(int k) const { return (k + 0.5) * length_mm / sections; }
};

struct CodeLayout {
  std::vector<CodeRow> rows;  // left to right
  int locations = 0;          // location ids 0 … locations − 1
};

// A right curve is the same piece as the left curve of its id, laid the other way round: a car
// turning right drives that piece backwards (as with Anki's curves, which are all one piece).
// Its rows are the left curve's, mirrored, with their ids running backwards (CodeRow::reversed).
CodeLayout codeLayout(const Piece& piece, const CodeGeometry& g = {});
// The piece a print of `piece` shows: a right curve is printed as its left curve.
Piece printedPiece(const Piece& piece);

// Where location id `location` lies on `piece`: its row, its section, and the section's centre
// as a fraction of the piece (forward); nothing when the piece has no such id. No allocation.
struct CodeSpot {
  int row = 0;
  int section = 0;
  double fraction = 0;
};
std::optional<CodeSpot> locateCode(const Piece& piece, int location, const CodeGeometry& g = {});
// locateCode's fraction for every location id of the piece at once, by id (the view keeps the
// current piece's: a position update then costs a lookup, not a walk over the rows).
std::vector<double> codeFractions(const Piece& piece, const CodeGeometry& g = {});
// The centres of section k's 9 strokes along its row, in forward order.
std::array<double, anki::optical::kStrokes> strokeCentres(const CodeRow& row, int section,
                                                          const CodeGeometry& g = {});

}  // namespace pitwall::sim
