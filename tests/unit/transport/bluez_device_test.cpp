// What the BlueZ client makes of a device's advertisement (engine/transport/bluez.hpp).
#include <doctest/doctest.h>

#include <algorithm>

#include "engine/transport/bluez.hpp"

using namespace pitwall;
using ble::Device;

namespace {
std::vector<std::uint8_t> ankiName(std::uint8_t state, const std::string& user) {
  std::vector<std::uint8_t> raw(8 + user.size() + 1, 0);  // reserved bytes and the final NUL
  raw[0] = state;
  raw[1] = 0x70;  // version 0x2b70, little-endian
  raw[2] = 0x2b;
  std::copy(user.begin(), user.end(), raw.begin() + 8);
  return raw;
}
}  // namespace

TEST_CASE("device: the raw Anki local name gives state, version and user name") {
  Device d;
  d.rawName = ankiName(0x30, "Red Devil");
  auto n = d.localName();
  CHECK(d.stateKnown());
  CHECK(n.user_name == "Red Devil");
  CHECK(n.version == 0x2b70);
  CHECK(n.full_battery);
  CHECK(n.low_battery);
  CHECK_FALSE(n.on_charger);
  d.rawName = ankiName(0x00, "Ghost");  // no state bit set is still an Anki name
  CHECK(d.stateKnown());
  CHECK(d.localName().user_name == "Ghost");
}

TEST_CASE("device: a plain name (a car emulator's) is the user name, state unknown") {
  Device d;
  d.rawName = std::vector<std::uint8_t>{'p', 'i', 't', 'w', 'a', 'l', 'l'};  // 'p' is 0x70
  CHECK_FALSE(d.stateKnown());
  CHECK(d.localName().user_name == "pitwall");
  Device named;
  named.name = "pitwall";
  CHECK_FALSE(named.stateKnown());
  CHECK(named.localName().user_name == "pitwall");
}

TEST_CASE("device: an emulated car's Anki-shaped Name gives state, version and a clean name") {
  // pitwall emulate-car's LocalName (anki::localNameText): the zeros of a real car's name are
  // 0x01, so BlueZ passes the whole name on in Name.
  Device d;
  d.name = std::string("\x10\x70\x2b\x01\x01\x01\x01\x01pitwall");
  CHECK(d.stateKnown());
  auto n = d.localName();
  CHECK(n.user_name == "pitwall");
  CHECK(n.version == 0x2b70);
  CHECK(n.full_battery);
  CHECK_FALSE(n.on_charger);
}

TEST_CASE("device: what BlueZ's Name keeps of an Anki name: state and version, no user name") {
  Device d;
  d.name = std::string("\x10p+");
  CHECK(d.stateKnown());
  auto n = d.localName();
  CHECK(n.full_battery);
  CHECK(n.version == 0x2b70);
  CHECK(n.user_name.empty());
  d.name = std::string("\x10");  // a version byte was zero: the version is unknown
  CHECK(d.localName().version == 0);
  Device none;
  CHECK_FALSE(none.stateKnown());
  CHECK(none.localName().user_name.empty());
}

TEST_CASE("device: Anki cars are told apart by the service UUID or the manufacturer data") {
  Device d;
  CHECK_FALSE(d.isAnki());
  d.uuids = {"BE15BEEF-6186-407E-8381-0BD89C4D8DF4"};  // any case
  CHECK(d.isAnki());
  Device m;
  m.manufacturer = anki::ManufacturerData{};
  CHECK(m.isAnki());
}
