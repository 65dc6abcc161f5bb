// Firmware versions as people write them (--firmware, docs/simulator.md "Firmware families").
#include "engine/protocol/anki/firmware.hpp"

#include <doctest/doctest.h>

#include <string>

using namespace pitwall::anki;

TEST_CASE("a firmware version is read in hex, with or without 0x, in either case") {
  CHECK(parseFirmware("0x266e").value() == 0x266e);
  CHECK(parseFirmware("0X266E").value() == 0x266e);
  CHECK(parseFirmware("2b70").value() == 0x2b70);
  CHECK(parseFirmware("ffff").value() == 0xffff);
  CHECK(parseFirmware("1").value() == 1);
  CHECK(olderLayouts(0x266e));
  CHECK_FALSE(olderLayouts(kFirmwareNewLayouts));
  CHECK_FALSE(olderLayouts(kFirmwareDefault));
}

TEST_CASE("what is not a version is refused with the text and what to give") {
  const std::string hostile[] = {"",
                                 "0x",
                                 "0",
                                 "0x0000",
                                 "10000",
                                 "0x1ffff",
                                 "-1",
                                 "2b70 ",
                                 " 2b70",
                                 "zz",
                                 "1e3.5",
                                 "0x2b7g",
                                 "\xff\xfe",
                                 std::string(5000, '7'),
                                 std::string("2b\0"
                                             "70",
                                             5)};
  for (const auto& text : hostile) {
    INFO("text: " << text.substr(0, 20));
    auto r = parseFirmware(text);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("is not a version") != std::string::npos);
    CHECK(r.error().find("0x266e") != std::string::npos);  // says what to give
    CHECK(r.error().size() < 300);                         // a long text is cut, not echoed
    CHECK(r.error().find('\xff') == std::string::npos);    // nor are bytes a terminal mangles
  }
  CHECK(parseFirmware("zz").error().find("'zz'") != std::string::npos);
}
