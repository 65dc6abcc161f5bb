// Decoding a position update, the most frequent frame a car sends (several per second per car).
// Target: ≤ 5 ns per frame (docs/performance.md).
#include <benchmark/benchmark.h>

#include <variant>

#include "engine/protocol/anki/codec.hpp"

namespace {

using namespace pitwall;

// A position update as a car on the start piece sends it (golden frame, made by the encoder).
anki::Frame goldenPositionFrame() {
  anki::PositionUpdate m;
  m.location_id = 17;
  m.piece_id = 34;
  m.offset_mm = -23.0f;
  m.speed_mm_s = 612;
  m.parsing_flags = 0x07;
  m.last_desired_speed_mm_s = 600;
  return anki::encode(m);
}

void BM_DecodePositionUpdate(benchmark::State& state) {
  const anki::Frame frame = goldenPositionFrame();
  auto check = anki::decode(frame.span());
  if (!check || !std::holds_alternative<anki::PositionUpdate>(*check)) {
    state.SkipWithError("the golden frame does not decode to a position update");
    return;
  }
  // decode() lives in another translation unit of a static library (no LTO), and the result
  // goes through DoNotOptimize, so the call cannot be folded away or hoisted out of the loop.
  for (auto _ : state) {
    auto decoded = anki::decode(frame.span());
    benchmark::DoNotOptimize(decoded);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DecodePositionUpdate);

}  // namespace
