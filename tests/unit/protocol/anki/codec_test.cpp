// The Anki codec against golden bytes (anki-overdrive.md, drive-sdk's own test vectors), both
// firmware layouts, frames longer than their layout, the short command forms cars obey, every
// decode error, and a brute-force check that decoding is total.
#include "engine/protocol/anki/codec.hpp"

#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "engine/protocol/anki/message_json.hpp"

using namespace pitwall::anki;

namespace {

std::vector<std::uint8_t> bytes(std::string_view hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < hex.size(); i += 3) {
    out.push_back(static_cast<std::uint8_t>(std::stoi(std::string(hex.substr(i, 2)), nullptr, 16)));
  }
  return out;
}

std::string hex(std::span<const std::uint8_t> data) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  for (const auto b : data) {
    if (!out.empty()) out += ' ';
    out += kDigits[b >> 4];
    out += kDigits[b & 0x0f];
  }
  return out;
}

struct Golden {
  Message message;
  std::string_view hex;
};

// One vector per layout. Floats chosen to be exact: -68 = c2880000, -23.5 = c1bc0000,
// 23 = 41b80000, 20 = 41a00000.
const std::vector<Golden>& goldens() {
  static const std::vector<Golden> table = {
      // controller → vehicle
      {Disconnect{}, "01 0d"},
      {PingRequest{}, "01 16"},     // drive-sdk test vector
      {VersionRequest{}, "01 18"},  // drive-sdk test vector
      {BatteryRequest{}, "01 1a"},  // drive-sdk test vector
      {SetLights{.mask = 0x44}, "02 1d 44"},
      {SetSpeed{.speed_mm_s = 1000, .accel_mm_s2 = 25000, .respect_limit = false},
       "06 24 e8 03 a8 61 00"},  // drive-sdk test vector
      {SetSpeed{.speed_mm_s = 600, .accel_mm_s2 = 1000, .respect_limit = true},
       "06 24 58 02 e8 03 01"},
      {ChangeLane{.h_speed_mm_s = 1000, .h_accel_mm_s2 = 10000, .offset_mm = 20.0f},
       "0b 25 e8 03 10 27 00 00 a0 41 00 00"},  // drive-sdk test vector
      {ChangeLane{.h_speed_mm_s = 250,
                  .h_accel_mm_s2 = 1000,
                  .offset_mm = -68.0f,
                  .hop_intent = 1,
                  .tag = 7},
       "0b 25 fa 00 e8 03 00 00 88 c2 01 07"},
      {CancelLaneChange{}, "01 26"},
      {SetOffset{.offset_mm = -23.5f}, "05 2c 00 00 bc c1"},
      {Turn{.type = TurnType::UTurn, .trigger = TurnTrigger::Immediate}, "03 32 03 00"},
      {Turn{.type = TurnType::Left, .trigger = TurnTrigger::Intersection}, "03 32 01 01"},
      {LightsPattern{
           .channel_count = 2,
           .channels = {{{.channel = 0, .effect = 3, .start = 0, .end = 14, .cycles_per_10s = 10},
                         {.channel = 3, .effect = 1, .start = 14, .end = 0, .cycles_per_10s = 5},
                         {}}}},
       "11 33 02 00 03 00 0e 0a 03 01 0e 00 05 00 00 00 00 00"},
      {SetConfig{.super_code_parse_mask = 0x01, .track_material = 1}, "03 45 01 01"},
      {SdkMode{.on = true, .flags = 0x01}, "03 90 01 01"},  // drive-sdk test vector
      {SdkMode{.on = false, .flags = 0x00}, "03 90 00 00"},
      // vehicle → controller
      {PingResponse{}, "01 17"},
      {VersionResponse{.version = 0x2b6e}, "03 19 6e 2b"},
      {BatteryResponse{.millivolts = 3920}, "03 1b 50 0f"},
      {PositionUpdate{.location_id = 14,
                      .piece_id = 36,
                      .offset_mm = -68.0f,
                      .speed_mm_s = 600,
                      .parsing_flags = 0x47,
                      .last_recv_lane_change_id = 2,
                      .last_exec_lane_change_id = 2,
                      .last_desired_lane_change_speed_mm_s = 300,
                      .last_desired_speed_mm_s = 600},
       "10 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02"},
      {TransitionUpdate{.piece_idx = 0,
                        .prev_piece_idx = -1,
                        .offset_mm = 23.0f,
                        .driving_direction = std::nullopt,
                        .last_recv_lane_change_id = 3,
                        .last_exec_lane_change_id = 3,
                        .last_desired_lane_change_speed_mm_s = 250,
                        .average_follow_line_drift_px = -2,
                        .had_lane_change_activity = 1,
                        .uphill_counter = 0,
                        .downhill_counter = 1,
                        .left_wheel_distance_cm = 56,
                        .right_wheel_distance_cm = 57},
       "11 29 00 ff 00 00 b8 41 03 03 fa 00 fe 01 00 01 38 39"},
      {TransitionUpdate{.piece_idx = 0,
                        .prev_piece_idx = -1,
                        .offset_mm = 23.0f,
                        .driving_direction = 1,
                        .last_recv_lane_change_id = 3,
                        .last_exec_lane_change_id = 3,
                        .last_desired_lane_change_speed_mm_s = 250,
                        .average_follow_line_drift_px = -2,
                        .had_lane_change_activity = 1,
                        .uphill_counter = 0,
                        .downhill_counter = 1,
                        .left_wheel_distance_cm = 56,
                        .right_wheel_distance_cm = 57},
       "12 29 00 ff 00 00 b8 41 01 03 03 fa 00 fe 01 00 01 38 39"},  // before firmware 0x2b6e
      {IntersectionUpdate{.piece_idx = 0,
                          .offset_mm = -23.5f,
                          .intersection_code = 1,
                          .is_exiting = 0,
                          .mm_since_last_transition_bar = 120,
                          .mm_since_last_intersection_code = 45},
       "0c 2a 00 00 00 bc c1 01 00 78 00 2d 00"},
      {IntersectionUpdate{.piece_idx = 0,
                          .offset_mm = -23.5f,
                          .intersection_code = 2,
                          .is_exiting = 1,
                          .mm_since_last_transition_bar = 120,
                          .mm_since_last_intersection_code = std::nullopt},
       "0a 2a 00 00 00 bc c1 02 01 78 00"},  // older firmware
      {Delocalized{}, "01 2b"},              // drive-sdk test vector
      {OffsetUpdate{.offset_mm = 20.0f, .lane_change_id = 5}, "06 2d 00 00 a0 41 05"},
      {SpeedUpdate{.desired_mm_s = 600, .accel_mm_s2 = 1000, .actual_mm_s = -3},
       "07 36 58 02 e8 03 fd ff"},
      {SpeedUpdate{.desired_mm_s = 250, .accel_mm_s2 = {}, .actual_mm_s = {}},
       "03 36 fa 00"},  // before firmware 0x2b6e (IBM's 0x266e car, ../shared/realdata)
      {CarStatus{.on_track = true, .on_charger = false, .low_battery = {}, .fully_charged = {}},
       "03 3f 01 00"},
      {CarStatus{.on_track = true, .on_charger = true, .low_battery = false, .fully_charged = true},
       "05 3f 01 01 00 01"},
      {LaneChangeUpdate{.current_offset_mm = -23.5f,
                        .target_offset_mm = 23.0f,
                        .h_speed_mm_s = 400,
                        .v_speed_mm_s = -3,
                        .lane_change_id = 9},
       "0f 41 00 00 bc c1 00 00 b8 41 90 01 fd ff 09 00"},
      {AutoRecoveryEntered{}, "01 43"},
      {AutoRecoverySucceeded{}, "01 44"},
      {Collision{.side = 1, .front_back = 0}, "03 4d 01 00"},
      {CycleOvertime{.count = 3, .average_us = 1500, .max_us = 4200},
       "0b 86 03 00 dc 05 00 00 68 10 00 00"},
  };
  return table;
}

Unknown unknownOf(std::string_view h) {
  const auto b = bytes(h);
  Unknown u{.id = b[1], .raw = {}};
  std::copy(b.begin(), b.end(), u.raw.bytes.begin());
  u.raw.length = static_cast<std::uint8_t>(b.size());
  return u;
}

DecodeError errorOf(std::string_view h) {
  const auto b = bytes(h);
  const auto r = decode(b);
  REQUIRE_FALSE(r.ok());
  return r.error();
}

}  // namespace

namespace doctest {
template <>
struct StringMaker<Message> {
  static String convert(const Message& m) { return toJson(m).dump().c_str(); }
};
}  // namespace doctest

TEST_CASE("every message kind has a golden vector") {
  std::vector<bool> seen(std::variant_size_v<Message>, false);
  for (const auto& g : goldens()) seen[g.message.index()] = true;
  seen[Message(Unknown{}).index()] = true;  // the unknown kind has its own test below
  for (std::size_t i = 0; i < seen.size(); ++i) {
    INFO("variant index " << i);
    CHECK(seen[i]);
  }
}

TEST_CASE("every message encodes to exactly its golden bytes") {
  for (const auto& g : goldens()) {
    INFO(name(g.message) << " expected " << g.hex);
    CHECK(hex(encode(g.message).span()) == g.hex);
  }
}

TEST_CASE("golden bytes decode to the message with every field as expected") {
  for (const auto& g : goldens()) {
    INFO(name(g.message) << " from " << g.hex);
    const auto r = decode(bytes(g.hex));
    REQUIRE(r.ok());
    CHECK(*r == g.message);
  }
}

TEST_CASE("every message survives encode then decode unchanged") {
  for (const auto& g : goldens()) {
    const auto r = decode(encode(g.message).span());
    REQUIRE(r.ok());
    CHECK(*r == g.message);
  }
}

TEST_CASE("drive-sdk's test vectors are reproduced byte for byte") {
  CHECK(hex(encode(SdkMode{.on = true, .flags = 0x01}).span()) == "03 90 01 01");
  CHECK(hex(encode(SetSpeed{.speed_mm_s = 1000, .accel_mm_s2 = 25000}).span()) ==
        "06 24 e8 03 a8 61 00");
  CHECK(hex(encode(ChangeLane{.h_speed_mm_s = 1000, .h_accel_mm_s2 = 10000, .offset_mm = 20.0f})
                .span()) == "0b 25 e8 03 10 27 00 00 a0 41 00 00");
  CHECK(hex(encode(Delocalized{}).span()) == "01 2b");
}

TEST_CASE("names are kebab-case and ids match the protocol tables") {
  CHECK(name(SetSpeed{}) == "set-speed");
  CHECK(name(PositionUpdate{}) == "position-update");
  CHECK(name(TransitionUpdate{}) == "transition-update");
  CHECK(name(SdkMode{}) == "sdk-mode");
  CHECK(name(PingRequest{}) == "ping-request");
  CHECK(name(unknownOf("01 99")) == "unknown");
  CHECK(messageId(PositionUpdate{}) == 0x27);
  CHECK(messageId(SdkMode{}) == 0x90);
  CHECK(messageId(unknownOf("01 99")) == 0x99);
  for (const auto& g : goldens()) CHECK(messageId(g.message) == bytes(g.hex)[1]);
}

TEST_CASE("an old-firmware transition update carries the driving direction and shifts the rest") {
  const auto r = decode(bytes("12 29 01 02 00 00 b8 41 07 03 04 fa 00 fe 01 05 06 38 39"));
  REQUIRE(r.ok());
  const auto& t = std::get<TransitionUpdate>(*r);
  CHECK(t.driving_direction == std::optional<std::uint8_t>(7));
  CHECK(t.last_recv_lane_change_id == 3);
  CHECK(t.last_exec_lane_change_id == 4);
  CHECK(t.last_desired_lane_change_speed_mm_s == 250);
  CHECK(t.right_wheel_distance_cm == 57);
}

TEST_CASE("an old-firmware intersection update has no distance since the last code") {
  const auto r = decode(bytes("0a 2a 00 00 00 bc c1 01 00 78 00"));
  REQUIRE(r.ok());
  const auto& i = std::get<IntersectionUpdate>(*r);
  CHECK_FALSE(i.mm_since_last_intersection_code.has_value());
  CHECK(i.mm_since_last_transition_bar == 120);
}

TEST_CASE("firmware 0x266e's speed update has one field: the others are absent, not zero") {
  const auto r = decode(bytes("03 36 00 00"));  // IBM's captured frame (../shared/realdata)
  REQUIRE(r.ok());
  const auto& s = std::get<SpeedUpdate>(*r);
  CHECK(s.desired_mm_s == 0);
  CHECK_FALSE(s.accel_mm_s2.has_value());
  CHECK_FALSE(s.actual_mm_s.has_value());
  CHECK(hex(encode(*r).span()) == "03 36 00 00");
  // written long as soon as one newer field is set; the other goes out as zero
  CHECK(hex(encode(SpeedUpdate{.desired_mm_s = 1, .accel_mm_s2 = {}, .actual_mm_s = 2}).span()) ==
        "07 36 01 00 00 00 02 00");
  const auto cut = errorOf("05 36 fa 00 d4 30");
  CHECK(cut.kind == DecodeError::Kind::TooShort);
  CHECK(cut.expected == 8);
}

TEST_CASE("a version response with 4 payload bytes reads the first u16 and is written short") {
  const auto r = decode(bytes("05 19 6e 2b 01 02"));
  REQUIRE(r.ok());
  CHECK(std::get<VersionResponse>(*r).version == 0x2b6e);
  CHECK(hex(encode(*r).span()) == "03 19 6e 2b");
}

TEST_CASE("a set-speed with the newer firmware's trailing byte is accepted") {
  const auto r = decode(bytes("07 24 e8 03 a8 61 00 01"));
  REQUIRE(r.ok());
  CHECK(std::get<SetSpeed>(*r) == SetSpeed{.speed_mm_s = 1000, .accel_mm_s2 = 25000});
}

TEST_CASE("a lane-change update without the last byte is accepted") {
  const auto r = decode(bytes("0e 41 00 00 bc c1 00 00 b8 41 90 01 fd ff 09"));
  REQUIRE(r.ok());
  CHECK(std::get<LaneChangeUpdate>(*r).lane_change_id == 9);
}

TEST_CASE("a car status is written long as soon as one newer field is set") {
  CHECK(hex(encode(CarStatus{.on_track = true, .low_battery = true, .fully_charged = {}}).span()) ==
        "05 3f 01 00 01 00");
}

TEST_CASE("an unknown id decodes to its raw bytes and encodes back to them") {
  const auto raw = bytes("04 99 01 02 03");
  const auto r = decode(raw);
  REQUIRE(r.ok());
  const auto& u = std::get<Unknown>(*r);
  CHECK(u.id == 0x99);
  CHECK(hex(u.raw.span()) == "04 99 01 02 03");
  CHECK(hex(encode(*r).span()) == "04 99 01 02 03");
  CHECK(hex(encode(Unknown{.id = 0x3c, .raw = {}}).span()) == "01 3c");
}

// decode() reads a position update before any other check (docs/performance.md "Decode"): a
// frame of its length is one only when both its size byte and its id say so.
TEST_CASE("a frame of a position update's length is read as one only with its size byte and id") {
  const auto position = decode(bytes("10 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02"));
  REQUIRE(position.ok());
  CHECK(std::get<PositionUpdate>(*position).speed_mm_s == 600);

  const auto says_more = errorOf("11 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02");
  CHECK(says_more.kind == DecodeError::Kind::SizeMismatch);
  CHECK(says_more.expected == 18);

  const auto transition = errorOf("10 29 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02");
  CHECK(transition.kind == DecodeError::Kind::TooShort);  // 0x29 has 18 or 19 bytes
  CHECK(transition.id == 0x29);

  const auto unknown = decode(bytes("10 ee 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02"));
  REQUIRE(unknown.ok());
  CHECK(std::get<Unknown>(*unknown).raw.length == 17);
}

TEST_CASE("no bytes at all is an empty-frame error") {
  const auto r = decode({});
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().kind == DecodeError::Kind::Empty);
  CHECK(r.error().message().find("empty") != std::string::npos);
}

TEST_CASE("more than 20 bytes is a too-big error naming the id and the lengths") {
  std::vector<std::uint8_t> big(21, 0);
  big[0] = 20;
  big[1] = 0x27;
  const auto r = decode(big);
  REQUIRE_FALSE(r.ok());
  const auto& e = r.error();
  CHECK(e.kind == DecodeError::Kind::TooBig);
  CHECK(e.id == 0x27);
  CHECK(e.received == 21);
  CHECK(e.message().find("0x27") != std::string::npos);
  CHECK(e.message().find("21 bytes") != std::string::npos);
  CHECK(e.message().find("20 bytes") != std::string::npos);
}

TEST_CASE("a size byte that disagrees with the bytes received is a size-mismatch error") {
  const auto e = errorOf("10 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01");  // says 17, is 15
  CHECK(e.kind == DecodeError::Kind::SizeMismatch);
  CHECK(e.id == 0x27);
  CHECK(e.expected == 17);
  CHECK(e.received == 15);
  CHECK(e.message().find("0x27") != std::string::npos);
  CHECK(e.message().find("17 bytes") != std::string::npos);
  CHECK(e.message().find("15 bytes") != std::string::npos);
}

TEST_CASE("a known id with too few payload bytes is a too-short error") {
  const auto e = errorOf("0f 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58");
  CHECK(e.kind == DecodeError::Kind::TooShort);
  CHECK(e.id == 0x27);
  CHECK(e.expected == 17);
  CHECK(e.received == 16);
  CHECK(e.message().find("0x27") != std::string::npos);
  CHECK(e.message().find("position-update") != std::string::npos);
  CHECK(e.message().find("17 bytes") != std::string::npos);
  CHECK(e.message().find("16 bytes") != std::string::npos);
}

TEST_CASE("a length between an old and a new layout is a cut-short new layout") {
  const auto intersection = errorOf("0b 2a 00 00 00 bc c1 01 00 78 00 2d");
  CHECK(intersection.kind == DecodeError::Kind::TooShort);
  CHECK(intersection.expected == 13);
  const auto status = errorOf("04 3f 01 00 01");
  CHECK(status.kind == DecodeError::Kind::TooShort);
  CHECK(status.expected == 6);
  CHECK(status.message().find("0x3f") != std::string::npos);
}

// anki-overdrive.md **Decision**: a firmware that appends a field must not lose its frames.
TEST_CASE("a position update with a byte appended is read by its layout and the byte kept") {
  const auto plain = bytes("10 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02");
  const auto longer = bytes("11 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02 aa");
  const auto r = decode(longer);
  REQUIRE(r.ok());
  CHECK(*r == *decode(plain));
  CHECK(std::get<PositionUpdate>(*r).speed_mm_s == 600);
  CHECK(hex(extraBytes(longer)) == "aa");
  CHECK(extraBytes(plain).empty());
}

TEST_CASE("every known id takes extra bytes up to the 20 a frame may have") {
  const auto ping = bytes("13 16 01 02 03 04 05 06 07 08 09 0a 0b 0c 0d 0e 0f 10 11 12");
  const auto r = decode(ping);
  REQUIRE(r.ok());
  CHECK(std::holds_alternative<PingRequest>(*r));
  CHECK(extraBytes(ping).size() == 18);
  CHECK(hex(extraBytes(bytes("02 16 00"))) == "00");
  CHECK(hex(extraBytes(bytes("04 2d 00 00 b8"))).empty());  // too short: no extras, an error
}

TEST_CASE("a message with two layouts is read by the longer one when the frame is longer still") {
  // 0x29 is 18 or 19 bytes; 20 is the old-firmware layout (with the driving direction) + 1 byte.
  const auto frame = bytes("13 29 00 00 00 00 b8 41 01 03 03 fa 00 fe 01 00 01 38 39 5a");
  const auto r = decode(frame);
  REQUIRE(r.ok());
  const auto& t = std::get<TransitionUpdate>(*r);
  CHECK(t.driving_direction == std::optional<std::uint8_t>(1));
  CHECK(t.right_wheel_distance_cm == 57);
  CHECK(hex(extraBytes(frame)) == "5a");
  // A car status past its newer form keeps both newer fields.
  const auto status = bytes("06 3f 01 00 01 00 07");
  REQUIRE(decode(status).ok());
  CHECK(std::get<CarStatus>(*decode(status)).low_battery == std::optional<bool>(true));
  CHECK(hex(extraBytes(status)) == "07");
}

TEST_CASE("a frame that fits its layout, an unknown id and a refused frame have no extra bytes") {
  CHECK(extraBytes(bytes("07 24 e8 03 a8 61 00 01")).empty());  // set speed's documented size 7
  CHECK(extraBytes(bytes("05 19 6e 2b 01 02")).empty());        // the version's 4-byte form
  CHECK(extraBytes(bytes("04 99 01 02 03")).empty());           // all of it is Unknown::raw
  CHECK(extraBytes(bytes("05 16 00")).empty());                 // size mismatch
  CHECK(extraBytes({}).empty());
  std::vector<std::uint8_t> big(21, 0);
  big[0] = 20;
  big[1] = 0x16;
  CHECK(extraBytes(big).empty());  // too big
}

TEST_CASE("encoding a message read from a longer frame gives the frame without the extra bytes") {
  const auto r = decode(bytes("11 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02 aa"));
  REQUIRE(r.ok());
  CHECK(hex(encode(*r).span()) == "10 27 0e 24 00 00 88 c2 58 02 47 02 02 2c 01 58 02");
}

// anki-overdrive.md **Decision**: py-drivesdk's set_speed and stop leave out the last byte.
TEST_CASE("the vehicle side reads a set speed without its last byte as respect-limit 0") {
  const auto shortForm = bytes("05 24 f4 01 f4 01");
  const auto e = decode(shortForm);
  REQUIRE_FALSE(e.ok());  // the controller side's decode stays strict
  CHECK(e.error().kind == DecodeError::Kind::TooShort);
  const auto r = decodeCommand(shortForm);
  REQUIRE(r.ok());
  CHECK(std::get<SetSpeed>(*r) ==
        SetSpeed{.speed_mm_s = 500, .accel_mm_s2 = 500, .respect_limit = false});
  const auto stop = decodeCommand(bytes("05 24 00 00 f4 01"));
  REQUIRE(stop.ok());
  CHECK(std::get<SetSpeed>(*stop).speed_mm_s == 0);
}

TEST_CASE("the vehicle side reads whole frames as decode() does and refuses other short forms") {
  for (const auto& g : goldens()) {
    INFO(g.hex);
    const auto r = decodeCommand(bytes(g.hex));
    REQUIRE(r.ok());
    CHECK(*r == g.message);
  }
  CHECK(decodeCommand(bytes("04 24 f4 01 f4")).error().kind == DecodeError::Kind::TooShort);
  CHECK(decodeCommand(bytes("03 24 f4 01")).error().kind == DecodeError::Kind::TooShort);
  CHECK(decodeCommand(bytes("05 24 f4 01 f4")).error().kind == DecodeError::Kind::SizeMismatch);
  CHECK(decodeCommand(bytes("0a 25 e8 03 10 27 00 00 a0 41 00")).error().kind ==
        DecodeError::Kind::TooShort);
  CHECK(decodeCommand(bytes("00")).error().kind == DecodeError::Kind::TooShort);
  CHECK(decodeCommand({}).error().kind == DecodeError::Kind::Empty);
}

TEST_CASE("a lone size byte is an error that says the id is missing") {
  const auto alone = errorOf("00");
  CHECK(alone.kind == DecodeError::Kind::TooShort);
  CHECK(alone.message().find("without an id") != std::string::npos);
  const auto promised = errorOf("05");
  CHECK(promised.kind == DecodeError::Kind::SizeMismatch);
  CHECK(promised.message().find("6 bytes") != std::string::npos);
}

namespace {

// Whether encode(decode(x)) must give x back. Decoding forgets exactly these things: booleans
// sent as bytes other than 0/1, the trailing byte of a size-7 set-speed, the two extra bytes of
// a long version response, the last byte of a lane-change update, and the bytes past the longest
// layout (those are extraBytes(x)).
bool canonical(std::span<const std::uint8_t> x) {
  if (!extraBytes(x).empty()) return false;
  const auto is01 = [&](std::size_t at) { return x[at] <= 1; };
  switch (x[1]) {
    case id::kSetSpeed:
      return x[0] == 6 && is01(6);
    case id::kSdkMode:
      return is01(2);
    case id::kCarStatus:
      for (std::size_t i = 2; i < x.size(); ++i) {
        if (!is01(i)) return false;
      }
      return true;
    case id::kVersionResponse:
      return x[0] == 3;
    case id::kLaneChangeUpdate:
      return x[0] == 15 && x[15] == 0;
    default:
      return true;
  }
}

}  // namespace

TEST_CASE("decoding is total: every length and id decodes or fails cleanly, and re-encodes") {
  std::mt19937 rng(20240611);
  std::size_t decoded = 0, exact = 0, withExtra = 0;
  for (std::size_t length = 0; length <= 24; ++length) {
    for (int id = 0; id < 256; ++id) {
      for (int shape = 0; shape < 3; ++shape) {
        std::vector<std::uint8_t> x(length);
        for (auto& b : x) b = static_cast<std::uint8_t>(shape == 1 ? rng() & 1 : rng());
        if (length >= 1 && shape != 2) x[0] = static_cast<std::uint8_t>(length - 1);
        if (length >= 2) x[1] = static_cast<std::uint8_t>(id);

        const auto r = decode(x);
        if (!r.ok()) {
          const auto& e = r.error();
          if (length == 0) CHECK(e.kind == DecodeError::Kind::Empty);
          if (length > 20) CHECK(e.kind == DecodeError::Kind::TooBig);
          if (length >= 2 && e.message().find("0x") == std::string::npos) {
            FAIL_CHECK("error without an id: " << e.message());
          }
          continue;
        }
        ++decoded;
        const auto extra = extraBytes(x);
        if (!extra.empty()) {
          // The same message as the frame cut to its layout, with the size byte to match.
          ++withExtra;
          std::vector<std::uint8_t> cut(x.begin(), x.end() - static_cast<long>(extra.size()));
          cut[0] = static_cast<std::uint8_t>(cut.size() - 1);
          const auto plain = decode(cut);
          if (!plain.ok() || !(encode(*plain) == encode(*r)))
            FAIL_CHECK(hex(x) << " does not read as " << hex(cut) << " does");
        }
        const Frame again = encode(*r);
        if (again.length < 2 || again.bytes[0] != again.length - 1) {
          FAIL_CHECK("malformed re-encoding of " << hex(x) << ": " << hex(again.span()));
        }
        if (canonical(x)) {
          ++exact;
          if (hex(again.span()) != hex(x))
            FAIL_CHECK(hex(x) << " re-encodes as " << hex(again.span()));
        } else {
          // Not canonical: one round trip reaches the canonical form, which then stays put.
          const auto twice = decode(again.span());
          REQUIRE(twice.ok());
          if (!(encode(*twice) == again)) FAIL_CHECK(hex(x) << " does not settle on one encoding");
        }
      }
    }
  }
  CHECK(decoded > 0);
  CHECK(exact > 0);
  CHECK(withExtra > 0);
}
