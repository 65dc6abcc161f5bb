#pragma once
// The frames the benchmarks feed the engine.
#include "engine/protocol/anki/codec.hpp"

namespace pitwall::bench {

// A typical position update (piece 39, location 0, offset 23 mm, 640 mm/s); benchmarks vary its
// location byte (index 2) so that every event differs from the last.
inline anki::Frame positionFrame() {
  anki::PositionUpdate m;
  m.location_id = 0;
  m.piece_id = 39;
  m.offset_mm = 23.0f;
  m.speed_mm_s = 640;
  m.parsing_flags = 0x07;
  m.last_desired_speed_mm_s = 650;
  return anki::encode(m);
}

}  // namespace pitwall::bench
