#include "engine/sim/code_layout.hpp"

#include <algorithm>
#include <cmath>

namespace pitwall::sim {

double CodeGeometry::width(anki::optical::Width w) const {
  switch (w) {
    case anki::optical::Width::Thin:
      return thin_mm;
    case anki::optical::Width::Thick:
      return thick_mm;
    case anki::optical::Width::Wide:
      return wide_mm;
    case anki::optical::Width::None:
      break;
  }
  return 0;
}

namespace {

CodeRow rowOf(const Piece& piece, int i, int first_location, const CodeGeometry& g) {
  CodeRow row;
  row.offset_mm = (i - (g.rows - 1) / 2.0) * g.row_pitch_mm;
  row.length_mm = piece.length(row.offset_mm);
  row.sections = static_cast<int>(std::floor(row.length_mm / g.section_min_mm + 1e-9));
  row.first_location = first_location;
  return row;
}

}  // namespace

Piece printedPiece(const Piece& piece) {
  Piece out = piece;
  if (out.turn < 0) out.turn = 1;
  return out;
}

CodeLayout codeLayout(const Piece& piece, const CodeGeometry& g) {
  CodeLayout out;
  const Piece printed = printedPiece(piece);
  out.rows.reserve(static_cast<std::size_t>(g.rows));
  for (int i = 0; i < g.rows; ++i) {
    out.rows.push_back(rowOf(printed, i, out.locations, g));
    out.locations += out.rows.back().sections;
  }
  if (piece.turn < 0) {  // the left curve's rows, seen driving it backwards
    std::reverse(out.rows.begin(), out.rows.end());
    for (CodeRow& row : out.rows) {
      row.offset_mm = -row.offset_mm;
      row.reversed = true;
    }
  }
  return out;
}

std::optional<CodeSpot> locateCode(const Piece& piece, int location, const CodeGeometry& g) {
  const Piece printed = printedPiece(piece);
  int first = 0;
  for (int i = 0; i < g.rows && location >= 0; ++i) {
    CodeRow row = rowOf(printed, i, first, g);
    if (location < first + row.sections) {
      int k = location - first;
      if (piece.turn < 0) {  // driven backwards: the row and the section from the other end
        k = row.sections - 1 - k;
        return CodeSpot{g.rows - 1 - i, k, row.sectionCentre(k) / row.length_mm};
      }
      return CodeSpot{i, k, row.sectionCentre(k) / row.length_mm};
    }
    first += row.sections;
  }
  return std::nullopt;
}

std::vector<double> codeFractions(const Piece& piece, const CodeGeometry& g) {
  std::vector<double> out;
  for (int location = 0;; ++location) {  // (the rows, walked once per id: a piece entered)
    auto spot = locateCode(piece, location, g);
    if (!spot) return out;
    out.push_back(spot->fraction);
  }
}

std::array<double, anki::optical::kStrokes> strokeCentres(const CodeRow& row, int section,
                                                          const CodeGeometry& g) {
  std::array<double, anki::optical::kStrokes> out;
  const double centre = row.sectionCentre(section);
  for (int j = 0; j < anki::optical::kStrokes; ++j)
    out[static_cast<std::size_t>(j)] =
        centre + (j - (anki::optical::kStrokes - 1) / 2.0) * g.stroke_pitch_mm;
  return out;
}

}  // namespace pitwall::sim
