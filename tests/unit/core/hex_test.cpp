#include "engine/core/hex.hpp"

#include <doctest/doctest.h>

using namespace pitwall;

TEST_CASE("hex: bytes as text, with or without a separator, and one byte as 0x..") {
  std::vector<std::uint8_t> bytes{0x06, 0x24, 0xe8, 0x03};
  CHECK(toHex(bytes) == "06 24 e8 03");
  CHECK(toHex(bytes, "") == "0624e803");
  CHECK(toHex(std::vector<std::uint8_t>{}) == "");
  CHECK(hexByte(0x0d) == "0x0d");
  CHECK(hexByte(0xff) == "0xff");
}

TEST_CASE("hex: text back to bytes, every byte value, and the errors named") {
  std::vector<std::uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<std::uint8_t>(i);
  CHECK(fromHex(toHex(all, "")).value() == all);
  CHECK(fromHex("0624E8").value() == std::vector<std::uint8_t>{0x06, 0x24, 0xe8});
  CHECK(fromHex("").value().empty());
  CHECK(fromHex("062").error() == "odd number of hex digits (3)");
  CHECK(fromHex("06zz").error() == "\"zz\" is not a hex byte");
  CHECK(fromHex("0 24").error() == "\"0 \" is not a hex byte");
}
