#pragma once
// A frame of a protocol whose frames have a small upper size (Anki: 20 bytes, MindRoad: 16):
// the bytes inline, no allocation.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

namespace pitwall {

template <std::size_t N>
struct BoundedFrame {
  static constexpr std::size_t kMax = N;
  std::array<std::uint8_t, N> bytes{};
  std::uint8_t length = 0;
  std::span<const std::uint8_t> span() const { return {bytes.data(), length}; }
  bool operator==(const BoundedFrame& o) const {
    return length == o.length && std::equal(bytes.begin(), bytes.begin() + length, o.bytes.begin());
  }
};

}  // namespace pitwall
