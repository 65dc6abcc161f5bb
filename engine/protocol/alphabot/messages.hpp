#pragma once
// The Alphabot's messages as values, independent of how they travel (../shared/protocols/
// alphabot.md): the WLAN packet codec (wlan_codec.hpp) and the BLE characteristic codec
// (ble_codec.hpp) both turn bytes into these and these into bytes. Units: cm, degrees.
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace pitwall::alphabot {

// The toggle bit field (2 bytes; a 1 enables). Byte 1 holds the settings, byte 2 the logging
// switches; bit 7 is the most significant (alphabot.md §3).
struct Toggles {
  std::uint8_t settings = 0;
  std::uint8_t logging = 0;
  bool operator==(const Toggles&) const = default;
};

// ---- requests (client → robot) ----
struct Drive {            // WLAN 0x01; BLE DRIVE_STEER (steer first there)
  std::int8_t speed = 0;  // negative: backwards
  std::int8_t steer = 0;  // negative: left
  bool operator==(const Drive&) const = default;
};
struct MeasureDistance {  // WLAN 0x02; BLE SENSOR request, kind distance
  std::int16_t degree = 0;
  bool operator==(const MeasureDistance&) const = default;
};
struct CalibrateSteering {  // WLAN 0x03; BLE CALIBRATE 1
  bool operator==(const CalibrateSteering&) const = default;
};
struct CalibrateCompass {  // WLAN 0x04; BLE CALIBRATE 2
  bool operator==(const CalibrateCompass&) const = default;
};
struct SetToggles {  // WLAN 0x05 (0xC0 accepted on decode); BLE TOGGLE
  Toggles toggles;
  bool operator==(const SetToggles&) const = default;
};
struct Ping {             // WLAN 0x06
  std::int64_t time = 0;  // when the client sent it (its own clock)
  bool operator==(const Ping&) const = default;
};
struct SetAnchor {  // WLAN 0x07
  std::uint8_t id = 0;
  std::int16_t x = 0, y = 0;
  bool operator==(const SetAnchor&) const = default;
};
struct NavigateTo {  // WLAN 0x08; BLE TARGET_NAVI
  std::int16_t x = 0, y = 0;
  bool operator==(const NavigateTo&) const = default;
};
struct AddObstacle {  // WLAN 0x09; BLE OBSTACLE 1 (width/height one byte each there)
  std::int16_t x = 0, y = 0;
  std::uint16_t width = 0, height = 0;
  bool operator==(const AddObstacle&) const = default;
};
struct RemoveObstacleById {  // WLAN 0x0A; BLE OBSTACLE 3 (by id)
  std::uint8_t id = 0;
  bool operator==(const RemoveObstacleById&) const = default;
};
struct RemoveObstacleAt {  // WLAN 0x0B; BLE OBSTACLE 3 (by position)
  std::int16_t x = 0, y = 0;
  bool operator==(const RemoveObstacleAt&) const = default;
};
struct ClearObstacles {  // WLAN 0x0C; BLE OBSTACLE 4
  bool operator==(const ClearObstacles&) const = default;
};
using Request = std::variant<Drive, MeasureDistance, CalibrateSteering, CalibrateCompass,
                             SetToggles, Ping, SetAnchor, NavigateTo, AddObstacle,
                             RemoveObstacleById, RemoveObstacleAt, ClearObstacles>;

// ---- responses (robot → client) ----
struct Distance {  // WLAN 0x81; BLE SENSOR answer, kind distance
  std::int16_t degree = 0;
  std::uint16_t distance = 0;  // cm
  bool operator==(const Distance&) const = default;
};
struct Position {  // WLAN 0x82; BLE SENSOR answer, kind positioning
  std::int16_t x = 0, y = 0;
  bool operator==(const Position&) const = default;
};
struct Waypoint {
  std::int16_t x = 0, y = 0;
  bool operator==(const Waypoint&) const = default;
};
struct Path {  // WLAN 0x83 (decision: u8 count, count × (x, y)); BLE PATH_FINDING
  std::vector<Waypoint> waypoints;
  bool operator==(const Path&) const = default;
};
struct Compass {  // WLAN 0x84; BLE SENSOR answer, kind compass
  std::int16_t degree = 0;
  bool operator==(const Compass&) const = default;
};
struct PingReply {  // WLAN 0x85: the request's time echoed
  std::int64_t time = 0;
  bool operator==(const PingReply&) const = default;
};
struct ObstacleRegistered {  // WLAN 0x86; BLE OBSTACLE 2
  std::uint8_t id = 0;
  std::int16_t x = 0, y = 0;
  std::uint16_t width = 0, height = 0;
  bool operator==(const ObstacleRegistered&) const = default;
};
// BLE only: SENSOR answers of kinds map size and positioning anchor; CALIBRATE 0.
struct MapSize {
  std::uint8_t length = 0, width = 0;  // as the robot reports them (one byte each)
  bool operator==(const MapSize&) const = default;
};
struct AnchorPosition {
  std::uint8_t id = 0;
  std::int16_t x = 0, y = 0;
  bool operator==(const AnchorPosition&) const = default;
};
struct CalibrationFinished {
  bool operator==(const CalibrationFinished&) const = default;
};
using Response = std::variant<Distance, Position, Path, Compass, PingReply, ObstacleRegistered,
                              MapSize, AnchorPosition, CalibrationFinished>;

}  // namespace pitwall::alphabot
