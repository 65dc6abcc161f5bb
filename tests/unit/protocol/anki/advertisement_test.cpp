// What an Anki car advertises: manufacturer data in both shapes, the local name, model names.
#include "engine/protocol/anki/advertisement.hpp"

#include <doctest/doctest.h>

#include <string>
#include <vector>

using namespace pitwall::anki;

namespace {
std::vector<std::uint8_t> operator""_b(const char* s, std::size_t n) {
  return {reinterpret_cast<const std::uint8_t*>(s), reinterpret_cast<const std::uint8_t*>(s) + n};
}
}  // namespace

TEST_CASE("eight raw manufacturer bytes give model and big-endian identifier") {
  const std::vector<std::uint8_t> raw{0xBE, 0xEF, 0x00, 0x08, 0x12, 0x34, 0x56, 0x78};
  const auto r = parseManufacturerData(raw);
  REQUIRE(r.ok());
  CHECK(r->product_id == 0xBEEF);
  CHECK(r->model_id == 8);
  CHECK(r->identifier == 0x12345678u);
}

TEST_CASE("BlueZ's key plus six bytes gives the same result, with the key signed or not") {
  const std::vector<std::uint8_t> value{0x00, 0x08, 0x12, 0x34, 0x56, 0x78};
  for (int key : {0xEFBE, -4162}) {
    INFO("key " << key);
    const auto r = parseManufacturerData(key, value);
    REQUIRE(r.ok());
    CHECK(r->product_id == 0xBEEF);
    CHECK(r->model_id == 8);
    CHECK(r->identifier == 0x12345678u);
  }
}

TEST_CASE("a foreign manufacturer key is refused with the key and Anki's") {
  const std::vector<std::uint8_t> value{0x00, 0x08, 0x12, 0x34, 0x56, 0x78};
  const auto r = parseManufacturerData(0x004C, value);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().find("76") != std::string::npos);
  CHECK(r.error().find("0xEFBE") != std::string::npos);
}

TEST_CASE("raw manufacturer data not starting with BE EF is refused") {
  const std::vector<std::uint8_t> raw{0x4C, 0x00, 0x00, 0x08, 0x12, 0x34, 0x56, 0x78};
  const auto r = parseManufacturerData(raw);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().find("0x4C00") != std::string::npos);
  CHECK(r.error().find("0xBEEF") != std::string::npos);
}

TEST_CASE("manufacturer data too short is refused with its length") {
  const std::vector<std::uint8_t> raw{0xBE, 0xEF, 0x00, 0x08};
  const auto r = parseManufacturerData(raw);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().find("4 bytes") != std::string::npos);
  const auto v = parseManufacturerData(0xEFBE, std::span(raw).first(3));
  REQUIRE_FALSE(v.ok());
  CHECK(v.error().find("3 bytes") != std::string::npos);
}

TEST_CASE("the local name gives state bits, version and the NUL-terminated user name") {
  const auto raw = "\x50\x6e\x2b\x00\x00\x00\x00\x00Skull\x00\x00junk"_b;
  const auto n = parseLocalName(raw);
  CHECK(n.full_battery);
  CHECK_FALSE(n.low_battery);
  CHECK(n.on_charger);
  CHECK(n.version == 0x2b6e);
  CHECK(n.user_name == "Skull");
}

TEST_CASE("a user name without a NUL runs to the end of the data") {
  const auto n = parseLocalName(
      "\x20\x01\x00\x00\x00\x00\x00\x00"
      "Drive"_b);
  CHECK(n.low_battery);
  CHECK_FALSE(n.full_battery);
  CHECK(n.version == 1);
  CHECK(n.user_name == "Drive");
}

TEST_CASE("a local name cut short gives what could be read") {
  CHECK(parseLocalName({}).user_name.empty());
  const auto state_only = parseLocalName("\x40"_b);
  CHECK(state_only.on_charger);
  CHECK(state_only.version == 0);
  const auto no_name = parseLocalName("\x10\x6e\x2b\x00"_b);
  CHECK(no_name.full_battery);
  CHECK(no_name.version == 0x2b6e);
  CHECK(no_name.user_name.empty());
}

TEST_CASE("a user name that is not valid UTF-8 is kept printable") {
  const auto n = parseLocalName("\x00\x00\x00\x00\x00\x00\x00\x00R\xffx\xc3\xa9"_b);
  CHECK(n.user_name == "R\xEF\xBF\xBDx\xC3\xA9");
}

TEST_CASE("a text local name has the binary one's layout with filler for the zeros") {
  LocalName name;
  name.full_battery = true;
  name.version = 0x2b70;
  name.user_name = "pitwall";
  const auto text = localNameText(name);
  REQUIRE(text.ok());
  CHECK(*text == std::string("\x10\x70\x2b\x01\x01\x01\x01\x01pitwall"));
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(text->data()),
                                            text->size());
  CHECK(isAnkiLocalName(bytes));
  const auto back = parseLocalName(bytes);
  CHECK(back.full_battery);
  CHECK_FALSE(back.low_battery);
  CHECK_FALSE(back.on_charger);
  CHECK(back.version == 0x2b70);
  CHECK(back.user_name == "pitwall");
}

TEST_CASE("py-drivesdk's reading of the text name: byte 0 without the charger bit, UTF-8 from 8") {
  // py-drivesdk (anki/control/controller.py, vehicle.py) takes a car when its local name,
  // encoded as UTF-8, has bit 6 of byte 0 clear and bytes 8.. decode as UTF-8.
  LocalName name;
  name.low_battery = true;
  name.version = 0x2b6e;
  name.user_name = "Röd";  // two-byte characters stay whole
  const auto text = localNameText(name);
  REQUIRE(text.ok());
  CHECK((static_cast<std::uint8_t>((*text)[0]) & 0x40) == 0);
  CHECK(text->substr(8) == "Röd");
  CHECK(text->find('\0') == std::string::npos);
  name.on_charger = true;  // a car on its charger says so, and such a client passes it over
  CHECK((static_cast<std::uint8_t>((*localNameText(name))[0]) & 0x40) != 0);
}

TEST_CASE("a text local name is refused where a byte would be NUL or half a character") {
  LocalName name;
  name.full_battery = true;
  name.version = 0x2b70;
  name.user_name = "pitwall";
  LocalName no_state = name;
  no_state.full_battery = false;
  REQUIRE_FALSE(localNameText(no_state).ok());
  CHECK(localNameText(no_state).error().find("NUL") != std::string::npos);
  LocalName zero_byte = name;
  zero_byte.version = 0x2b00;
  REQUIRE_FALSE(localNameText(zero_byte).ok());
  CHECK(localNameText(zero_byte).error().find("0x2B00") != std::string::npos);
  LocalName high_byte = name;
  high_byte.version = 0x802b;
  CHECK_FALSE(localNameText(high_byte).ok());
  LocalName bad_name = name;
  bad_name.user_name = "R\xff";
  CHECK_FALSE(localNameText(bad_name).ok());
}

TEST_CASE("a car's user name is 1 to 12 bytes of UTF-8 without control characters") {
  CHECK(userNameProblem("pitwall").empty());
  CHECK(userNameProblem("Red Devil 12").empty());  // 12 bytes
  CHECK(userNameProblem("Rød Djævel").empty());
  CHECK(userNameProblem("").find("empty") != std::string::npos);
  CHECK(userNameProblem("Red Devil 123").find("13 bytes") != std::string::npos);
  CHECK(userNameProblem("bad\x01").find("control") != std::string::npos);
  CHECK(userNameProblem("tab\tname").find("control") != std::string::npos);
  CHECK(userNameProblem("del\x7f").find("control") != std::string::npos);
  CHECK(userNameProblem("R\xc3").find("UTF-8") != std::string::npos);
}

TEST_CASE("an Anki-shaped local name is told from a text name by its state and reserved bytes") {
  CHECK(isAnkiLocalName("\x50\x6e\x2b\x00\x00\x00\x00\x00Skull"_b));    // a real car's
  CHECK(isAnkiLocalName("\x00\x6e\x2b\x00\x00\x00\x00\x00"_b));         // state 0, no name
  CHECK(isAnkiLocalName("\x10\x70\x2b\x01\x01\x01\x01\x01pitwall"_b));  // emulate-car's
  CHECK_FALSE(isAnkiLocalName("pitwall emulated"_b));  // 'p' is a state byte, but letters follow
  CHECK_FALSE(isAnkiLocalName("\x10\x70\x2b\x00\x00"_b));               // too short
  CHECK_FALSE(isAnkiLocalName("\x11\x70\x2b\x00\x00\x00\x00\x00x"_b));  // bit 0x01 is no state
  CHECK_FALSE(isAnkiLocalName("Pa\x21 \x01\x01\x01\x01x"_b));  // a text name: byte 3 printable
}

// tests/realdata/advertisements: a real car's reserved bytes are 01 and then printable ones.
TEST_CASE("the local names real cars sent are read as Anki names: state, version, user name") {
  const auto drive =
      "\x50\x20\x21\x01\x20\x20\x5a\x39"
      "AA3 TOMMY\x00"_b;  // drive-sdk's
  REQUIRE(isAnkiLocalName(drive));
  const auto a = parseLocalName(drive);
  CHECK(a.full_battery);
  CHECK(a.on_charger);
  CHECK(a.version == 0x2120);
  CHECK(a.user_name == "AA3 TOMMY");
  const auto dynamo =
      "\x10\x60\x30\x01\x20\x20\x20\x20"
      "Drive\x00"_b;  // ble_monitor #1256
  REQUIRE(isAnkiLocalName(dynamo));
  const auto b = parseLocalName(dynamo);
  CHECK(b.full_battery);
  CHECK(b.version == 0x3060);
  CHECK(b.user_name == "Drive");
}

TEST_CASE("model ids name the car, unknown ones print as model-n") {
  CHECK(modelName(1) == "Kourai");
  CHECK(modelName(8) == "Groundshock");
  CHECK(modelName(9) == "Skull");
  CHECK(modelName(14) == "Big Bang");
  CHECK(modelName(20) == "Nuke Phantom");
  CHECK(modelName(13) == "model-13");
  CHECK(modelName(0) == "model-0");
  CHECK(modelName(200) == "model-200");
}

TEST_CASE("default car names come from the model and are made unique") {
  CHECK(uniqueCarName(8, {}) == "groundshock");
  CHECK(uniqueCarName(8, {"groundshock"}) == "groundshock-2");
  CHECK(uniqueCarName(8, {"groundshock", "groundshock-2"}) == "groundshock-3");
  CHECK(uniqueCarName(14, {}) == "big-bang");  // spaces become dashes
  CHECK(uniqueCarName(200, {}) == "model-200");
}
