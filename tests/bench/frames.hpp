#pragma once
// The frames the benchmarks feed the engine, and a link that takes them in.
#include <string>

#include "engine/protocol/anki/codec.hpp"
#include "engine/transport/link.hpp"

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

// A link that accepts everything and delivers nothing: frames enter through AnkiCar::receive.
class BenchLink final : public Link {
 public:
  bool send(std::span<const std::uint8_t>) override { return true; }
  bool connected() const override { return true; }
  void disconnect() override {}
  std::string address() const override { return "bench"; }
};

// Byte 2 of a position update is its location id ([size][id][location][piece]…).
constexpr std::size_t kLocationByte = 2;

}  // namespace pitwall::bench
