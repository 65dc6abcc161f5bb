#pragma once
// bytes ⇄ messages for the Alphabot's BLE GATT service: one characteristic per function
// (../shared/protocols/alphabot.md §2, bit fields §3; docs/robots.md). Pure: no I/O.
// Decoding is total: every (characteristic, bytes) gives a message or a BleCodecError that names
// the characteristic, what is wrong and the lengths.
//
// Both directions are here: a client encodes requests and decodes what the robot notifies or
// serves on a read; the robot side (the fake BlueZ's Alphabot, `pitwall decode alphabot-ble`)
// decodes requests and encodes answers.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/result.hpp"
#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot::ble {

enum class Characteristic : std::uint8_t {
  DriveSteer,
  Sensor,
  Toggle,
  Obstacle,
  PingClient,
  Calibrate,
  TargetNavi,
  PathFinding,
};

// alphabot.md §2.
inline constexpr const char* kDriveSteerUuid = "a04295f7-eaa8-4536-b3a4-4e7ae4d72dc2";
inline constexpr const char* kSensorUuid = "4c999381-35e2-4af4-8443-ee8b9fe56ba0";
inline constexpr const char* kToggleUuid = "fce001d4-864a-48f4-9c95-de928f1da07b";
inline constexpr const char* kObstacleUuid = "60db37c7-afeb-4d40-bb17-a19a07d6fc95";
inline constexpr const char* kPingClientUuid = "117ad3a5-b257-4465-abd4-7dc12a4cf77d";
inline constexpr const char* kCalibrateUuid = "d39e8d54-8019-46c8-a977-db13871bac59";
inline constexpr const char* kTargetNaviUuid = "f56f0a15-52ae-4ad5-bfe1-557eed983618";
inline constexpr const char* kPathFindingUuid = "8dad4c9a-1a1c-4a42-a522-ded592f4ed99";

struct CharacteristicInfo {
  Characteristic id;
  const char* name;  // as in the reference: "DRIVE_STEER", …
  const char* uuid;  // lower case
  std::size_t size;  // the value's size in the reference table
  bool write, notify;
};
const std::array<CharacteristicInfo, 8>& characteristics();
const CharacteristicInfo& info(Characteristic c);
// "DRIVE_STEER", "drive-steer", "drive_steer" or the UUID (any case); nullopt when unknown.
std::optional<Characteristic> characteristicNamed(std::string_view nameOrUuid);
std::optional<Characteristic> characteristicByUuid(std::string_view uuid);

// The SENSOR bit field's kinds (bits 6–4 of its first byte).
enum class SensorKind : std::uint8_t {
  Distance = 0,
  Compass = 1,
  MapSize = 2,
  Positioning = 3,
  Anchor = 4,
};
inline constexpr std::uint8_t kSensorAnswerBit = 0x80;  // bit 7: 0 request, 1 answer

// BLE-only values, beside messages.hpp's Request and Response:
// a SENSOR request that only names its kind (ask for the compass, the map size, the position).
struct SensorQuery {
  SensorKind kind = SensorKind::Compass;
  bool operator==(const SensorQuery&) const = default;
};
// TOGGLE as the robot notifies (or serves) it: its settings now.
struct TogglesReport {
  Toggles toggles;
  bool operator==(const TogglesReport&) const = default;
};
// PINGCLIENT's one byte, notified by the robot (a heartbeat; its value is the robot's).
struct Heartbeat {
  std::uint8_t value = 0;
  bool operator==(const Heartbeat&) const = default;
};

// PATH_FINDING read while the robot still computes the path (count byte 0xFF): read again.
struct PathPending {
  bool operator==(const PathPending&) const = default;
};

using ClientMessage = std::variant<Request, SensorQuery>;  // what a client writes
// What a robot notifies or serves on a read.
using RobotMessage = std::variant<Response, TogglesReport, Heartbeat, PathPending>;

// One GATT write (or notification, or read value).
struct BleValue {
  Characteristic characteristic = Characteristic::DriveSteer;
  std::vector<std::uint8_t> bytes;
  bool operator==(const BleValue&) const = default;
};

struct BleCodecError {
  Characteristic characteristic = Characteristic::DriveSteer;
  std::string message;  // one sentence, starting with the characteristic's name
};

// Client → robot. Ping has no BLE write (it is a read of PINGCLIENT, see the link): an error.
// Values the characteristic cannot carry (obstacle width 300 in one byte, degree 400, anchor
// id 16) are errors naming the value; nothing is encoded.
Result<BleValue, BleCodecError> encode(const Request& request);
Result<BleValue, BleCodecError> encode(const SensorQuery& query);
// Robot → client (the fake robot). PingReply has no BLE form (the read is the answer): an error.
Result<BleValue, BleCodecError> encode(const Response& response);
BleValue encode(const TogglesReport& report);
BleValue encode(const Heartbeat& heartbeat);
BleValue encode(const PathPending& pending);

// What a robot makes of a write to `c`.
Result<ClientMessage, BleCodecError> decodeRequest(Characteristic c,
                                                   std::span<const std::uint8_t> bytes);
// What a client makes of a notification from, or a read of, `c`.
Result<RobotMessage, BleCodecError> decodeResponse(Characteristic c,
                                                   std::span<const std::uint8_t> bytes);

// PATH_FINDING's layout (decision, consistent with WLAN 0x83): u8 count (0–4), then count ×
// (i16 x, i16 y) little-endian, zero padding to 20 bytes. 0xFF as count: not computed yet.
inline constexpr std::size_t kPathFindingSize = 20;
inline constexpr std::size_t kMaxBleWaypoints = 4;
inline constexpr std::uint8_t kPathPending = 0xFF;
// OBSTACLE remove-one (sub-command 3) carries coordinates and an id; decision: id 0xFF means
// "by position", any other id means "by id" (coordinates then 0 and ignored).
inline constexpr std::uint8_t kRemoveByPosition = 0xFF;

}  // namespace pitwall::alphabot::ble

namespace pitwall::alphabot {

// For `pitwall decode alphabot-ble CHARACTERISTIC HEX`: decodes in the direction the bytes say
// (the SENSOR answer bit, the OBSTACLE sub-command, CALIBRATE 0; DRIVE_STEER, TOGGLE and
// TARGET_NAVI as written by a client; PINGCLIENT and PATH_FINDING as served by the robot) and
// gives message_json.hpp's object without "packet" plus "characteristic", "uuid" and
// "direction": "request"|"response"; the BLE-only values are named "sensor-query" (kind),
// "toggles" (toggles), "heartbeat" (value) and "path-pending". The error is one sentence (an
// unknown characteristic lists the known ones).
Result<nlohmann::json, std::string> decodeBle(std::string_view characteristic,
                                              std::span<const std::uint8_t> bytes);

}  // namespace pitwall::alphabot
