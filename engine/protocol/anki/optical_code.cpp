#include "engine/protocol/anki/optical_code.hpp"

namespace pitwall::anki::optical {

namespace {

Width bit(int value, int index) {  // index 0 = most significant
  return (value >> (kBits - 1 - index)) & 1 ? Width::Thick : Width::Thin;
}

// The bit a stroke's width stands for, or -1.
int bitOf(Width w) {
  return w == Width::Thick ? 1 : w == Width::Thin ? 0 : -1;
}

}  // namespace

const char* widthName(Width w) {
  switch (w) {
    case Width::None:
      return "none";
    case Width::Thin:
      return "thin";
    case Width::Thick:
      return "thick";
    case Width::Wide:
      return "wide";
  }
  return "?";
}

std::array<Stroke, kStrokes> encodeSection(int piece_id, int location_id) {
  std::array<Stroke, kStrokes> out;
  const Stroke boundary{Width::Thin, Width::Wide};
  out.front() = out.back() = boundary;
  for (int i = 0; i < kBits; ++i) out[1 + i] = {bit(piece_id, i), bit(location_id, i)};
  return out;
}

Result<Reading, std::string> decodeSection(std::span<const Stroke> strokes) {
  if (strokes.size() != kStrokes)
    return Unexpected<std::string>(std::to_string(strokes.size()) +
                                   " strokes where a section has 9 (a boundary, 7 bits, a "
                                   "boundary)");
  auto isBoundary = [](const Stroke& s, bool reversed) {
    return reversed ? s.left == Width::Wide && s.right == Width::Thin
                    : s.left == Width::Thin && s.right == Width::Wide;
  };
  const bool reversed = isBoundary(strokes.front(), true);
  if (!isBoundary(strokes.front(), reversed) || !isBoundary(strokes.back(), reversed))
    return Unexpected<std::string>(
        std::string("no boundary at both ends (first stroke ") + widthName(strokes.front().left) +
        "/" + widthName(strokes.front().right) + ", last " + widthName(strokes.back().left) + "/" +
        widthName(strokes.back().right) +
        "; a boundary is thin on one side, wide on the "
        "other)");
  Reading r;
  r.reversed = reversed;
  for (int i = 0; i < kBits; ++i) {
    // Reversed, the piece side is on the reader's right and the bits come last first.
    const Stroke& s = strokes[reversed ? kBits - i : 1 + i];
    const Width pieceSide = reversed ? s.right : s.left;
    const Width locationSide = reversed ? s.left : s.right;
    int p = bitOf(pieceSide), l = bitOf(locationSide);
    if (p < 0 || l < 0)
      return Unexpected<std::string>("bit " + std::to_string(i + 1) + " is " +
                                     widthName(p < 0 ? pieceSide : locationSide) + " on the " +
                                     (p < 0 ? "piece" : "location") +
                                     " side, where a bit is thin (0) or thick (1)");
    r.piece_id = r.piece_id << 1 | p;
    r.location_id = r.location_id << 1 | l;
  }
  return r;
}

}  // namespace pitwall::anki::optical
