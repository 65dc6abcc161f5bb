// The MindRoad codec against the seed's own examples (seed 002 §5), every instruction, every
// decode error, the stream decoder's framing, and a brute-force check that decoding is total.
#include "engine/protocol/mindroad/codec.hpp"

#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "engine/protocol/mindroad/command_text.hpp"
#include "engine/protocol/mindroad/message_json.hpp"

using namespace pitwall::mindroad;

namespace {

std::vector<std::uint8_t> bytes(std::initializer_list<int> b) {
  std::vector<std::uint8_t> out;
  for (int v : b) out.push_back(static_cast<std::uint8_t>(v));
  return out;
}

std::vector<std::uint8_t> encoded(const Instruction& i) {
  auto f = encode(i);
  return {f.span().begin(), f.span().end()};
}

Instruction parsed(std::vector<std::string> words) {
  auto r = parseCommand(words);
  REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error()));
  return *r;
}

std::string parseError(std::vector<std::string> words) {
  auto r = parseCommand(words);
  REQUIRE_FALSE(r.ok());
  return r.error();
}

}  // namespace

TEST_CASE(
    "mindroad: the seed's examples encode to its bytes: contact 0x10, full forward 22 7f 00") {
  CHECK(encoded(Contact{}) == bytes({0x10}));
  CHECK(encoded(Steering{127, 0}) == bytes({0x22, 0x7f, 0x00}));
  // §5.2: full backward, half right; the seed prints this header as 0010 0000, which breaks its
  // own rule — the header is 0x22 (two data bytes), the data bytes are as printed.
  CHECK(encoded(Steering{-128, 64}) == bytes({0x22, 0x80, 0x40}));
}

TEST_CASE(
    "mindroad: every instruction encodes with its id in the high nibble and its data length low") {
  CHECK(encoded(Stop{}) == bytes({0x00}));
  CHECK(encoded(MousePosition{80, 60}) == bytes({0x32, 80, 60}));
  CHECK(encoded(Buttons::fromId(Button::Automatic)) == bytes({0x41, 0x01}));
  CHECK(encoded(Buttons{0x05}) == bytes({0x41, 0x05}));
  CHECK(encoded(Ping{}) == bytes({0x50}));
  CHECK(encoded(PictureMode{Picture::Hsv}) == bytes({0x61, 0x01}));
  CHECK(encoded(PictureMode{Picture::Filter}) == bytes({0x61, 0x02}));
  CHECK(encoded(Shutdown{}) == bytes({0x70}));
}

TEST_CASE("mindroad: every instruction decodes back to itself") {
  const std::vector<Instruction> all = {Stop{},
                                        Contact{},
                                        Steering{127, 0},
                                        Steering{-128, 64},
                                        Steering{0, -1},
                                        MousePosition{1, 1},
                                        MousePosition{160, 120},
                                        Buttons{0},
                                        Buttons{255},
                                        Ping{},
                                        PictureMode{Picture::Rgb},
                                        PictureMode{Picture::Filter},
                                        Shutdown{}};
  for (const auto& i : all) {
    auto f = encode(i);
    auto back = decode(f.span());
    REQUIRE_MESSAGE(back.ok(), (back.ok() ? "" : back.error().message()));
    CHECK(*back == i);
  }
  auto s = decode(bytes({0x22, 0x80, 0x40}));
  REQUIRE(s.ok());
  CHECK(std::get<Steering>(*s).x == -128);
  CHECK(std::get<Steering>(*s).y == 64);
}

TEST_CASE("mindroad: unused ids 8 to 15 are a typed error naming the id") {
  for (int id = 8; id <= 15; ++id) {
    auto r = decode(bytes({id << 4}));
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().kind == DecodeError::Kind::UnusedId);
    CHECK(r.error().id == id);
    CHECK(r.error().message().find("instruction " + std::to_string(id) + " is unused") !=
          std::string::npos);
  }
  auto withData = decode(bytes({0x92, 1, 2}));
  REQUIRE_FALSE(withData.ok());
  CHECK(withData.error().message() ==
        "instruction 9 is unused (ids 8-15 stop the robot; used ids are 0-7), with 2 data bytes");
}

TEST_CASE(
    "mindroad: a header announcing a length its id does not have is an error naming both lengths") {
  auto r = decode(bytes({0x21, 0x7f}));
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().kind == DecodeError::Kind::WrongLength);
  CHECK(r.error().message() ==
        "instruction 2 (steering) takes 2 data bytes, the header announces 1");
  auto ping = decode(bytes({0x51, 0x00}));
  REQUIRE_FALSE(ping.ok());
  CHECK(ping.error().message() ==
        "instruction 5 (ping) takes 0 data bytes, the header announces 1");
}

TEST_CASE(
    "mindroad: bytes that disagree with the header's length nibble are an error naming both") {
  auto shortData = decode(bytes({0x22, 0x7f}));
  REQUIRE_FALSE(shortData.ok());
  CHECK(shortData.error().kind == DecodeError::Kind::LengthMismatch);
  CHECK(shortData.error().message() ==
        "instruction 2 (steering): the header announces 2 data bytes but 1 followed");
  auto extra = decode(bytes({0x10, 0x10}));
  REQUIRE_FALSE(extra.ok());
  CHECK(extra.error().message() ==
        "instruction 1 (contact): the header announces 0 data bytes but 1 followed");
  auto empty = decode(std::span<const std::uint8_t>{});
  REQUIRE_FALSE(empty.ok());
  CHECK(empty.error().kind == DecodeError::Kind::Empty);
}

TEST_CASE(
    "mindroad: a click outside the 160x120 picture and an unknown picture mode are range errors") {
  auto x = decode(bytes({0x32, 0, 60}));
  REQUIRE_FALSE(x.ok());
  CHECK(x.error().message() == "instruction 3 (mouse-position): x 0 is out of range 1..160");
  auto y = decode(bytes({0x32, 160, 121}));
  REQUIRE_FALSE(y.ok());
  CHECK(y.error().message() == "instruction 3 (mouse-position): y 121 is out of range 1..120");
  auto mode = decode(bytes({0x61, 3}));
  REQUIRE_FALSE(mode.ok());
  CHECK(mode.error().message() ==
        "instruction 6 (picture-mode): mode 3 is out of range 0..2 (0 rgb, 1 hsv, 2 filter)");
  CHECK(validate(MousePosition{161, 1}) == "click x 161 is out of range 1..160");
  CHECK(validate(MousePosition{1, 0}) == "click y 0 is out of range 1..120");
  CHECK_FALSE(validate(MousePosition{160, 120}).has_value());
}

TEST_CASE(
    "mindroad: decoding is total: every one- and two-byte string, and three-byte ones, decode or "
    "err") {
  int ok = 0, total = 0;
  auto check = [&](const std::vector<std::uint8_t>& b) {
    ++total;
    auto r = decode(b);
    if (r.ok()) {
      ++ok;
      CHECK(encoded(*r) == b);  // what decodes re-encodes to the same bytes
    } else {
      CHECK_FALSE(r.error().message().empty());
    }
  };
  for (int h = 0; h < 256; ++h) {
    check(bytes({h}));
    for (int a = 0; a < 256; ++a) {
      check(bytes({h, a}));
      for (int c : {0, 1, 60, 119, 120, 121, 159, 160, 161, 255}) check(bytes({h, a, c}));
    }
  }
  CHECK(total == 256 + 256 * 256 * 11);
  // stop, contact, ping, shutdown; 256 buttons; modes 0-2; every steering; clicks in range
  CHECK(ok == 4 + 256 + 3 + 256 * 10 + 160 * 4);  // y in {1, 60, 119, 120} of the sample
}

TEST_CASE(
    "mindroad: the contact answer K decodes on the robot-to-client side; any other byte does not") {
  CHECK(decodeAnswer(bytes({0x4b})).ok());
  auto other = decodeAnswer(bytes({0x4c}));
  REQUIRE_FALSE(other.ok());
  CHECK(other.error().message() ==
        "robot answer 0x4c is not the contact answer 0x4b (K), the only byte the robot sends");
  CHECK_FALSE(decodeAnswer(bytes({0x4b, 0x4b})).ok());
  // As an instruction 0x4b would be buttons with 11 data bytes: never valid from a client.
  CHECK_FALSE(decode(bytes({0x4b})).ok());
}

TEST_CASE("mindroad: the stream decoder frames instructions split across reads and merged in one") {
  StreamDecoder d;
  CHECK(d.feed(bytes({0x10, 0x22})).size() == 1);  // contact, then half a steering header
  CHECK(d.pending() == 1);
  CHECK(d.feed(bytes({0x7f})).empty());
  auto steer = d.feed(bytes({0x00, 0x50, 0x00}));
  REQUIRE(steer.size() == 3);
  CHECK(*steer[0] == Instruction{Steering{127, 0}});
  CHECK(*steer[1] == Instruction{Ping{}});
  CHECK(*steer[2] == Instruction{Stop{}});
  CHECK(d.pending() == 0);
}

TEST_CASE("mindroad: the stream decoder costs a bad instruction only itself") {
  StreamDecoder d;
  // unused id 9 with 2 data bytes, steering with 1 data byte, then a good ping
  auto out = d.feed(bytes({0x92, 0x01, 0x02, 0x21, 0x7f, 0x50}));
  REQUIRE(out.size() == 3);
  CHECK(out[0].error().kind == DecodeError::Kind::UnusedId);
  CHECK(out[1].error().kind == DecodeError::Kind::WrongLength);
  REQUIRE(out[2].ok());
  CHECK(*out[2] == Instruction{Ping{}});
}

TEST_CASE("mindroad: buttons keep the raw byte and offer both of the seed's readings") {
  Buttons automatic{1};
  REQUIRE(automatic.asId().has_value());
  CHECK(*automatic.asId() == Button::Automatic);
  CHECK(automatic.pressed(0));  // as a mask, byte 1 is button 0
  Buttons mask{0x05};
  CHECK_FALSE(mask.asId().has_value());
  CHECK(mask.pressed(0));
  CHECK_FALSE(mask.pressed(1));
  CHECK(mask.pressed(2));
  auto j = toJson(Buttons{0x05});
  CHECK(
      j.dump() ==
      R"({"button":null,"header":"0x41","id":4,"name":"buttons","pressed":["manual","sensitivity-up"],"raw":5})");
  CHECK(toJson(Buttons{0x10})["pressed"].dump() == R"(["bit-4"])");
}

TEST_CASE("mindroad: instructions as JSON name their fields") {
  CHECK(toJson(Steering{-128, 64}).dump() ==
        R"({"header":"0x22","id":2,"name":"steering","x":-128,"y":64})");
  CHECK(toJson(MousePosition{80, 60}).dump() ==
        R"({"header":"0x32","id":3,"name":"mouse-position","x":80,"y":60})");
  CHECK(toJson(PictureMode{Picture::Hsv}).dump() ==
        R"({"header":"0x61","id":6,"mode":"hsv","name":"picture-mode"})");
  CHECK(toJson(Contact{}).dump() == R"({"header":"0x10","id":1,"name":"contact"})");
}

TEST_CASE(
    "mindroad: instructions written as words parse, and bad words name the value and the range") {
  CHECK(parsed({"steer", "127", "0"}) == Instruction{Steering{127, 0}});
  CHECK(parsed({"steer", "-128", "0x40"}) == Instruction{Steering{-128, 64}});
  CHECK(parsed({"click", "80", "60"}) == Instruction{MousePosition{80, 60}});
  CHECK(parsed({"buttons", "automatic"}) == Instruction{Buttons{1}});
  CHECK(parsed({"buttons", "0x05"}) == Instruction{Buttons{5}});
  CHECK(parsed({"picture-mode", "hsv"}) == Instruction{PictureMode{Picture::Hsv}});
  CHECK(parsed({"contact"}) == Instruction{Contact{}});
  CHECK(parsed({"stop"}) == Instruction{Stop{}});
  CHECK(parsed({"ping"}) == Instruction{Ping{}});
  CHECK(parsed({"shutdown"}) == Instruction{Shutdown{}});
  CHECK(parseError({"steer", "128", "0"}) ==
        "steer x (forward/backward) 128 is out of range -128..127");
  CHECK(parseError({"steer", "1"}) ==
        "missing steer y (right/left) (-128..127); usage: steer X Y (-128..127 each)");
  CHECK(parseError({"click", "0", "60"}) == "click x 0 is out of range 1..160");
  CHECK(parseError({"click", "80", "121"}) == "click y 121 is out of range 1..120");
  CHECK(parseError({"click", "eighty", "1"}) ==
        "click x 'eighty' is not a whole number; expected 1..160");
  CHECK(parseError({"buttons", "256"}) == "buttons byte 256 is out of range 0..255");
  CHECK(parseError({"buttons", "turbo"}).find("button 'turbo' is unknown") == 0);
  CHECK(parseError({"picture-mode", "cmyk"}) ==
        "picture mode 'cmyk' is unknown; use rgb, hsv or filter");
  CHECK(parseError({"ping", "1"}) == "ping takes no arguments, got '1'");
  CHECK(parseError({"fly"}).find("unknown instruction 'fly'") == 0);
}
