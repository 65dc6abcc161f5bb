#pragma once
// Every MindRoad robot car instruction as a value type (../shared/protocols/mindroad.md, seed 002
// §3). An instruction is a header byte — high nibble the id (0–15), low nibble the number of data
// bytes that follow (0–15) — and its data. The robot answers only contact, with one byte, `K`.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <variant>

#include "engine/protocol/frame.hpp"

namespace pitwall::mindroad {

// An instruction as sent: header plus at most 15 data bytes.
using Frame = BoundedFrame<16>;

namespace id {
inline constexpr std::uint8_t kStop = 0;
inline constexpr std::uint8_t kContact = 1;
inline constexpr std::uint8_t kSteering = 2;
inline constexpr std::uint8_t kMousePosition = 3;
inline constexpr std::uint8_t kButtons = 4;
inline constexpr std::uint8_t kPing = 5;
inline constexpr std::uint8_t kPictureMode = 6;
inline constexpr std::uint8_t kShutdown = 7;
inline constexpr std::uint8_t kLastUsed = 7;  // 8–15 are unused: using one stops the robot
}  // namespace id

// The robot's one answer, to contact: 0100 1011, ASCII "K" (seed 002 §4).
inline constexpr std::uint8_t kContactAnswer = 0x4B;

// Ranges of the data values (seed 002 table 1).
inline constexpr int kClickMinX = 1, kClickMaxX = 160;
inline constexpr int kClickMinY = 1, kClickMaxY = 120;

struct Stop {
  bool operator==(const Stop&) const = default;
};
struct Contact {
  bool operator==(const Contact&) const = default;
};
// X forward (+) / backward (−), Y right (+) / left (−); signed bytes (seed 002 table 1, §5.2).
struct Steering {
  std::int8_t x = 0;
  std::int8_t y = 0;
  bool operator==(const Steering&) const = default;
};
// Where the user clicked in the 160×120 camera picture (colour pick), 1-based.
struct MousePosition {
  std::uint8_t x = kClickMinX;
  std::uint8_t y = kClickMinY;
  bool operator==(const MousePosition&) const = default;
};

enum class Button : std::uint8_t {
  Manual = 0,
  Automatic = 1,
  SensitivityUp = 2,
  SensitivityDown = 3
};
inline constexpr std::array<Button, 4> kButtons = {Button::Manual, Button::Automatic,
                                                   Button::SensitivityUp, Button::SensitivityDown};
std::string_view buttonName(Button b);  // "manual", "automatic", "sensitivity-up", …
std::optional<Button> buttonFromName(std::string_view name);

// The seed reads the data byte two ways: table 2 gives it as one button's id (0 manual …
// 3 sensitivity down, 4–254 unused), its example §5.2 as several pressed buttons at once.
// Decision (mindroad.md): keep the raw byte; offer both readings.
struct Buttons {
  std::uint8_t raw = 0;
  // Table 2's reading: the one button whose id the byte is (none for 4–255).
  std::optional<Button> asId() const {
    return raw <= 3 ? std::optional<Button>(static_cast<Button>(raw)) : std::nullopt;
  }
  // §5.2's reading: bit n set ⇔ button n pressed (bit 0 manual, bit 1 automatic, …, bits 4–7
  // buttons without a name).
  bool pressed(int bit) const { return bit >= 0 && bit < 8 && (raw >> bit) & 1; }
  static Buttons fromId(Button b) { return {static_cast<std::uint8_t>(b)}; }
  bool operator==(const Buttons&) const = default;
};

struct Ping {
  bool operator==(const Ping&) const = default;
};

enum class Picture : std::uint8_t { Rgb = 0, Hsv = 1, Filter = 2 };
std::string_view pictureName(Picture p);  // "rgb", "hsv", "filter"
std::optional<Picture> pictureFromName(std::string_view name);
struct PictureMode {
  Picture mode = Picture::Rgb;
  bool operator==(const PictureMode&) const = default;
};

struct Shutdown {
  bool operator==(const Shutdown&) const = default;
};

// Client → robot. The order is the ids' order: index() == id.
using Instruction =
    std::variant<Stop, Contact, Steering, MousePosition, Buttons, Ping, PictureMode, Shutdown>;

}  // namespace pitwall::mindroad
