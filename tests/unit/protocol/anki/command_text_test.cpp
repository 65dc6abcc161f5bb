// Commands written as words, as `pitwall encode anki MESSAGE ARGS…` takes them.
#include "engine/protocol/anki/command_text.hpp"

#include <doctest/doctest.h>

#include <sstream>
#include <string>
#include <vector>

#include "engine/protocol/anki/codec.hpp"

using namespace pitwall::anki;

namespace {

std::vector<std::string> split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The encoded frame of a command line, as hex; or the refusal, prefixed with "error: ".
std::string encoded(const std::string& line) {
  const auto r = parseCommand(split(line));
  if (!r.ok()) return "error: " + r.error();
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  const Frame frame = encode(*r);
  for (const auto b : frame.span()) {
    if (!out.empty()) out += ' ';
    out += kDigits[b >> 4];
    out += kDigits[b & 0x0f];
  }
  return out;
}

std::string refusal(const std::string& line) {
  const auto r = parseCommand(split(line));
  REQUIRE_FALSE(r.ok());
  return r.error();
}

bool mentions(const std::string& text, std::initializer_list<std::string_view> parts) {
  for (const auto p : parts) {
    if (text.find(p) == std::string::npos) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("each command form encodes to its exact frame") {
  CHECK(encoded("sdk-mode on") == "03 90 01 01");
  CHECK(encoded("set-speed 1000 25000") == "06 24 e8 03 a8 61 00");
  CHECK(encoded("change-lane 1000 10000 20") == "0b 25 e8 03 10 27 00 00 a0 41 00 00");
  CHECK(encoded("turn uturn") == "03 32 03 00");
  CHECK(encoded("ping") == "01 16");
  CHECK(encoded("version") == "01 18");
  CHECK(encoded("battery") == "01 1a");
  CHECK(encoded("disconnect") == "01 0d");
  CHECK(encoded("cancel-lane-change") == "01 26");
}

TEST_CASE("optional words take their defaults") {
  CHECK(encoded("set-speed 1000") == "06 24 e8 03 e8 03 00");  // accel 1000
  CHECK(encoded("set-speed 600 respect-limit") == "06 24 58 02 e8 03 01");
  CHECK(encoded("set-speed 600 2000 respect-limit") == "06 24 58 02 d0 07 01");
  CHECK(encoded("sdk-mode off") == "03 90 00 01");
  CHECK(encoded("sdk-mode on 0") == "03 90 01 00");
  CHECK(encoded("turn left intersection") == "03 32 01 01");
  CHECK(encoded("turn uturn-jump immediate") == "03 32 04 00");
}

TEST_CASE("the remaining forms encode their fields") {
  CHECK(encoded("change-lane 250 1000 -68 1 7") == "0b 25 fa 00 e8 03 00 00 88 c2 01 07");
  CHECK(encoded("set-offset -23.5") == "05 2c 00 00 bc c1");
  CHECK(encoded("lights 0x44") == "02 1d 44");
  CHECK(encoded("lights 68") == "02 1d 44");
  CHECK(encoded("config 1 vinyl") == "03 45 01 01");
  CHECK(encoded("config 0x0 plastic") == "03 45 00 00");
  CHECK(encoded("config 0 1") == "03 45 00 01");
}

TEST_CASE("a lights pattern is always 17 bytes with unused slots zero") {
  CHECK(encoded("lights-pattern 0 3 0 14 10") ==
        "11 33 01 00 03 00 0e 0a 00 00 00 00 00 00 00 00 00 00");
  CHECK(encoded("lights-pattern 0 3 0 14 10 3 1 14 0 5") ==
        "11 33 02 00 03 00 0e 0a 03 01 0e 00 05 00 00 00 00 00");
  CHECK(encoded("lights-pattern 0 0 1 1 0 1 0 2 2 0 2 0 3 3 0") ==
        "11 33 03 00 00 01 01 00 01 00 02 02 00 02 00 03 03 00");
}

TEST_CASE("the codec's own names are accepted for the short forms") {
  CHECK(encoded("ping-request") == "01 16");
  CHECK(encoded("set-lights 0x0f") == "02 1d 0f");
  CHECK(encoded("set-config 1 0") == "03 45 01 00");
}

TEST_CASE("an out-of-range number is refused with word, value and range") {
  CHECK(refusal("set-speed 2000") == "speed 2000 mm/s is out of range 0..1500 mm/s");
  CHECK(refusal("set-speed -5") == "speed -5 mm/s is out of range 0..1500 mm/s");
  CHECK(refusal("set-speed 500 30000") ==
        "acceleration 30000 mm/s² is out of range 0..25000 mm/s²");
  CHECK(refusal("change-lane 300 300 150") ==
        "offset 150 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal("change-lane 300 300 -75") ==
        "offset -75 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(refusal("set-offset 70.5") ==
        "offset 70.5 mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(encoded("set-offset -70") == "05 2c 00 00 8c c2");
  CHECK(mentions(refusal("lights-pattern 7 0 0 14 10"), {"slot 1 channel", "7", "0..5"}));
  CHECK(mentions(refusal("lights-pattern 0 0 0 15 10"), {"slot 1 end intensity", "15", "0..14"}));
  CHECK(mentions(refusal("change-lane 300 300 0 256 1"), {"hop intent", "256", "0..255"}));
}

TEST_CASE("a number too big for its field is refused before it is narrowed") {
  CHECK(refusal("set-speed 70000") == "speed 70000 mm/s is out of range 0..1500 mm/s");
  CHECK(mentions(refusal("set-speed 99999999999999999999999"), {"speed", "0..1500"}));
  CHECK(mentions(refusal("lights 256"), {"mask", "256", "0..255"}));
  CHECK(mentions(refusal("sdk-mode on 0x100"), {"flags", "0x100", "0..255"}));
  CHECK(mentions(refusal("set-offset 1e300"), {"offset", "1e300", "-70..70 mm"}));
}

TEST_CASE("offsets that are not finite are refused") {
  CHECK(refusal("set-offset nan") ==
        "offset nan mm is out of range -70..70 mm (beyond it the car leaves the road)");
  CHECK(mentions(refusal("change-lane 300 300 inf"), {"offset", "inf", "-70..70 mm"}));
}

TEST_CASE("a word that is not a number is refused with the range it should be in") {
  CHECK(refusal("set-speed fast") == "speed 'fast' is not a whole number; expected 0..1500 mm/s");
  CHECK(mentions(refusal("set-speed 12.5"), {"speed", "12.5", "0..1500"}));
  CHECK(mentions(refusal("set-offset left"), {"offset", "left", "-70..70 mm"}));
  CHECK(mentions(refusal("lights 0x"), {"mask", "0x", "0..255"}));
}

TEST_CASE("a word outside its choices is refused with the list of choices") {
  CHECK(refusal("turn sideways") ==
        "turn type 'sideways' is not one of none, left, right, uturn, uturn-jump");
  CHECK(mentions(refusal("turn left later"), {"later", "immediate, intersection"}));
  CHECK(mentions(refusal("sdk-mode maybe"), {"maybe", "off, on"}));
  CHECK(mentions(refusal("config 1 wood"), {"wood", "plastic, vinyl"}));
}

TEST_CASE("a missing word is refused naming it and the command's form") {
  CHECK(refusal("set-speed") ==
        "set-speed is missing speed; usage: set-speed SPEED [ACCEL] [respect-limit]");
  CHECK(mentions(refusal("change-lane 300 300"), {"missing offset", "change-lane HSPEED"}));
  CHECK(mentions(refusal("change-lane 300 300 0 1"), {"missing tag"}));
  CHECK(mentions(refusal("lights-pattern 0 3 0 14"), {"missing slot 1 cycles"}));
  CHECK(mentions(refusal("config 1"), {"missing track material"}));
  CHECK(mentions(refusal("turn"), {"missing turn type"}));
}

TEST_CASE("an extra word is refused naming it") {
  CHECK(refusal("ping now") == "unexpected word 'now' after ping; usage: ping");
  CHECK(mentions(refusal("set-speed 500 1000 respect-limit 3"), {"'3'", "set-speed SPEED"}));
  CHECK(mentions(refusal("set-offset 10 20"), {"'20'"}));
  CHECK(mentions(refusal("lights-pattern 0 0 0 0 0 1 1 1 1 1 2 2 2 2 2 3 3 3 3 3"),
                 {"at most 3", "'3'"}));
}

TEST_CASE("an unknown message name is refused with the list of known ones") {
  const auto e = refusal("warp 9");
  CHECK(
      mentions(e, {"'warp'", "sdk-mode", "set-speed", "change-lane", "lights-pattern", "config"}));
  CHECK(mentions(refusal(""), {"no message", "set-speed"}));
}

TEST_CASE("the command forms are listed for help texts") {
  const auto forms = commandForms();
  CHECK(forms.size() == 13);
  CHECK(forms.front() == "sdk-mode on|off [FLAGS]");
}
