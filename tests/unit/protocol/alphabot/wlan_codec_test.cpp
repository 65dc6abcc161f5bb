// The Alphabot's WLAN packets (alphabot.md §1): golden bytes for every request and response,
// the decisions (little-endian, 0xC0 alias, 0x83 layout), typed errors and the stream decoder.
#include "engine/protocol/alphabot/wlan_codec.hpp"

#include <doctest/doctest.h>

#include "engine/protocol/alphabot/command_text.hpp"
#include "engine/protocol/alphabot/message_json.hpp"
#include "engine/protocol/alphabot/toggles.hpp"

using namespace pitwall::alphabot;
using namespace pitwall::alphabot::wlan;
using B = std::vector<std::uint8_t>;

namespace {

Toggles named(std::initializer_list<const char*> names) {
  Toggles t;
  for (auto* n : names) setBit(t, *findToggle(n), true);
  return t;
}

template <class M>
void roundTrip(const M& message, const B& bytes) {
  CAPTURE(bytes.size());
  if constexpr (std::is_constructible_v<Request, M>) {
    CHECK(encode(Request{message}) == bytes);
    auto back = decode(bytes);
    REQUIRE(back.ok());
    CHECK(std::get<Request>(*back) == Request{message});
  } else {
    auto out = encode(Response{message});
    REQUIRE(out.ok());
    CHECK(*out == bytes);
    auto back = decode(bytes);
    REQUIRE(back.ok());
    CHECK(std::get<Response>(*back) == Response{message});
  }
}

}  // namespace

TEST_CASE("every alphabot request has its golden bytes, little-endian") {
  roundTrip(Drive{50, -10}, B{0x01, 0x32, 0xf6});
  roundTrip(MeasureDistance{-90}, B{0x02, 0xa6, 0xff});
  roundTrip(CalibrateSteering{}, B{0x03});
  roundTrip(CalibrateCompass{}, B{0x04});
  roundTrip(SetToggles{named({"collisionAvoidance", "positioning", "logCompass"})},
            B{0x05, 0x30, 0x10});
  roundTrip(Ping{12345}, B{0x06, 0x39, 0x30, 0, 0, 0, 0, 0, 0});
  roundTrip(Ping{-2}, B{0x06, 0xfe, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff});
  roundTrip(SetAnchor{1, 100, 200}, B{0x07, 0x01, 0x64, 0x00, 0xc8, 0x00});
  roundTrip(NavigateTo{300, -150}, B{0x08, 0x2c, 0x01, 0x6a, 0xff});
  roundTrip(AddObstacle{10, 20, 30, 400}, B{0x09, 0x0a, 0x00, 0x14, 0x00, 0x1e, 0x00, 0x90, 0x01});
  roundTrip(RemoveObstacleById{3}, B{0x0a, 0x03});
  roundTrip(RemoveObstacleAt{10, 20}, B{0x0b, 0x0a, 0x00, 0x14, 0x00});
  roundTrip(ClearObstacles{}, B{0x0c});
}

TEST_CASE("every alphabot WLAN response has its golden bytes") {
  roundTrip(Distance{90, 130}, B{0x81, 0x5a, 0x00, 0x82, 0x00});
  roundTrip(Position{172, -5}, B{0x82, 0xac, 0x00, 0xfb, 0xff});
  roundTrip(Path{{{10, 20}, {30, 40}}},
            B{0x83, 0x02, 0x0a, 0x00, 0x14, 0x00, 0x1e, 0x00, 0x28, 0x00});
  roundTrip(Path{}, B{0x83, 0x00});
  roundTrip(Compass{359}, B{0x84, 0x67, 0x01});
  roundTrip(PingReply{12345}, B{0x85, 0x39, 0x30, 0, 0, 0, 0, 0, 0});
  roundTrip(ObstacleRegistered{7, 180, 100, 40, 100},
            B{0x86, 0x07, 0xb4, 0x00, 0x64, 0x00, 0x28, 0x00, 0x64, 0x00});
}

TEST_CASE("byte order is a codec option: big-endian swaps the multi-byte fields only") {
  Options big{ByteOrder::Big};
  CHECK(encode(Request{NavigateTo{300, -150}}, big) == B{0x08, 0x01, 0x2c, 0xff, 0x6a});
  CHECK(encode(Request{SetToggles{named({"positioning", "logPosition"})}}, big) ==
        B{0x05, 0x20, 0x80});
  auto d = decode(B{0x81, 0x00, 0x5a, 0x00, 0x82}, big);
  REQUIRE(d.ok());
  CHECK(std::get<Response>(*d) == Response{Distance{90, 130}});
}

TEST_CASE("0xC0 decodes as the toggle request; we always encode 0x05") {
  auto d = decode(B{0xc0, 0x10, 0x00});
  REQUIRE(d.ok());
  CHECK(std::get<Request>(*d) == Request{SetToggles{named({"collisionAvoidance"})}});
  CHECK(encode(std::get<Request>(*d))[0] == 0x05);
}

TEST_CASE("decoding names what is wrong: unknown id, short and long packets") {
  auto empty = decode(B{});
  REQUIRE(!empty.ok());
  CHECK(empty.error().kind == DecodeError::Kind::Empty);

  auto unknown = decode(B{0x42, 0x00});
  REQUIRE(!unknown.ok());
  CHECK(unknown.error().kind == DecodeError::Kind::UnknownId);
  CHECK(unknown.error().message().find("unknown packet id 0x42") != std::string::npos);

  auto shortDrive = decode(B{0x01, 0x32});
  REQUIRE(!shortDrive.ok());
  CHECK(shortDrive.error().kind == DecodeError::Kind::TooShort);
  CHECK(shortDrive.error().message() == "packet 0x01 (drive) is 2 byte(s), expected 3");

  auto longPing = decode(B{0x85, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  REQUIRE(!longPing.ok());
  CHECK(longPing.error().kind == DecodeError::Kind::TooLong);
  CHECK(longPing.error().message() == "packet 0x85 (ping-reply) is 10 byte(s), expected 9");

  auto pathShort = decode(B{0x83, 0x02, 0x0a, 0x00, 0x14, 0x00});
  REQUIRE(!pathShort.ok());
  CHECK(pathShort.error().message() ==
        "packet 0x83 (path) is 6 byte(s), expected 10 (from its count)");
  auto pathNoCount = decode(B{0x83});
  REQUIRE(!pathNoCount.ok());
  CHECK(pathNoCount.error().kind == DecodeError::Kind::TooShort);
}

TEST_CASE("BLE-only answers and oversized paths are refused by the WLAN encoder") {
  CHECK(!encode(Response{MapSize{1, 2}}).ok());
  CHECK(!encode(Response{CalibrationFinished{}}).ok());
  Path big;
  big.waypoints.resize(256);
  auto e = encode(Response{big});
  REQUIRE(!e.ok());
  CHECK(e.error().find("255") != std::string::npos);
}

TEST_CASE("the stream decoder reassembles packets split and merged across reads") {
  B stream = {0x81, 0x5a, 0x00, 0x82, 0x00, 0x83, 0x01, 0x0a, 0x00, 0x14, 0x00, 0x84, 0x67, 0x01};
  // Every split point, one byte at a time and all at once, gives the same three packets.
  for (std::size_t chunk : {std::size_t{1}, std::size_t{2}, std::size_t{3}, stream.size()}) {
    CAPTURE(chunk);
    StreamDecoder d(StreamDecoder::Accept::Responses);
    std::vector<Response> got;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      auto n = std::min(chunk, stream.size() - at);
      d.feed(std::span<const std::uint8_t>(stream.data() + at, n));
      while (auto p = d.next()) {
        REQUIRE(p->ok());
        got.push_back(std::get<Response>(**p));
      }
    }
    REQUIRE(got.size() == 3);
    CHECK(got[0] == Response{Distance{90, 130}});
    CHECK(got[1] == Response{Path{{{10, 20}}}});
    CHECK(got[2] == Response{Compass{359}});
    CHECK(d.buffered() == 0);
  }
}

TEST_CASE("the stream decoder skips garbage to the next id and reports it once") {
  StreamDecoder d(StreamDecoder::Accept::Responses);
  B bytes = {0x42, 0x00, 0x13, 0x82, 0x0a, 0x00, 0x14, 0x00};
  d.feed(bytes);
  auto first = d.next();
  REQUIRE(first);
  REQUIRE(!first->ok());
  CHECK(first->error().kind == DecodeError::Kind::UnknownId);
  CHECK(first->error().received == 3);
  auto second = d.next();
  REQUIRE(second);
  REQUIRE(second->ok());
  CHECK(std::get<Response>(**second) == Response{Position{10, 20}});
  CHECK(!d.next());
}

TEST_CASE("a request id on the client's stream is reported as travelling the wrong way") {
  StreamDecoder d(StreamDecoder::Accept::Responses);
  d.feed(B{0x01, 0x32, 0xf6, 0x84, 0x00, 0x00});
  auto first = d.next();
  REQUIRE(first);
  REQUIRE(!first->ok());
  CHECK(first->error().kind == DecodeError::Kind::WrongDirection);
  CHECK(first->error().message().find("a request, where responses are expected") !=
        std::string::npos);
  auto second = d.next();
  REQUIRE(second);
  CHECK(second->ok());
}

TEST_CASE("toggle names map to the reference's bits, once for Lua and JSON") {
  CHECK(findToggle("compassCalibration")->bit == 7);
  CHECK(!findToggle("compassCalibration")->logging);
  CHECK(findToggle("exploreMode")->bit == 2);
  CHECK(findToggle("logGyroscope")->logging);
  CHECK(findToggle("logGyroscope")->bit == 0);
  CHECK(findToggle("warpDrive") == nullptr);
  Toggles t = named({"invite", "logPosition"});
  CHECK(t.settings == 0x40);
  CHECK(t.logging == 0x80);
  auto j = toJson(t);
  CHECK(j.dump() == R"({"logging":128,"on":["invite","logPosition"],"settings":64})");
}

TEST_CASE("decoded packets print with the reference table's field names") {
  CHECK(
      toJson(ObstacleRegistered{7, 180, 100, 40, 100}).dump() ==
      R"({"height":100,"id":7,"name":"obstacle-registered","packet":"0x86","width":40,"x":180,"y":100})");
  CHECK(toJson(Drive{50, -10}).dump() ==
        R"({"name":"drive","packet":"0x01","speed":50,"steer":-10})");
  CHECK(toJson(Path{{{1, 2}}}).dump() ==
        R"({"name":"path","packet":"0x83","waypoints":[{"x":1,"y":2}]})");
}

TEST_CASE("the encode text parser takes every form and refuses bad values with the range") {
  auto req = [](std::vector<std::string> w) { return parseRequest(w); };
  CHECK(*req({"drive", "50", "-10"}) == Request{Drive{50, -10}});
  CHECK(*req({"measure-distance", "90"}) == Request{MeasureDistance{90}});
  CHECK(*req({"toggles", "collisionAvoidance,positioning"}) ==
        Request{SetToggles{named({"collisionAvoidance", "positioning"})}});
  CHECK(*req({"toggles", "none"}) == Request{SetToggles{}});
  CHECK(*req({"ping", "0x10"}) == Request{Ping{16}});
  CHECK(*req({"anchor", "1", "100", "200"}) == Request{SetAnchor{1, 100, 200}});
  CHECK(*req({"navigate", "300", "150"}) == Request{NavigateTo{300, 150}});
  CHECK(*req({"add-obstacle", "1", "2", "3", "4"}) == Request{AddObstacle{1, 2, 3, 4}});
  CHECK(*req({"remove-obstacle", "3"}) == Request{RemoveObstacleById{3}});
  CHECK(*req({"remove-obstacle-at", "10", "20"}) == Request{RemoveObstacleAt{10, 20}});
  CHECK(*req({"clear-obstacles"}) == Request{ClearObstacles{}});
  CHECK(*req({"calibrate-steering"}) == Request{CalibrateSteering{}});
  CHECK(*req({"calibrate-compass"}) == Request{CalibrateCompass{}});

  CHECK(req({"drive", "128", "0"}).error().find("speed 128 is out of range -128..127") !=
        std::string::npos);
  CHECK(req({"drive", "1"}).error().find("missing steer") != std::string::npos);
  CHECK(req({"drive", "1", "x"}).error().find("'x' is not a whole number") != std::string::npos);
  CHECK(req({"drive", "1", "2", "3"}).error().find("unexpected extra argument '3'") !=
        std::string::npos);
  CHECK(req({"toggles", "warp"}).error().find("unknown toggle 'warp'; known: compassCalibration") !=
        std::string::npos);
  CHECK(req({"add-obstacle", "1", "2", "0", "4"})
            .error()
            .find("width (cm) 0 is out of range 1..65535") != std::string::npos);
  CHECK(req({"fly"}).error().find("unknown alphabot message 'fly'") != std::string::npos);
  CHECK(req({"ping", "99999999999999999999"}).error().find("out of range") != std::string::npos);
}
