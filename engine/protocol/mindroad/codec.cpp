// The MindRoad codec (../shared/protocols/mindroad.md; seed 002 §2–4).
#include "engine/protocol/mindroad/codec.hpp"

#include "engine/core/numbers.hpp"

#include <type_traits>

#include "engine/core/hex.hpp"

namespace pitwall::mindroad {

namespace {

constexpr std::array<std::string_view, 8> kNames = {
    "stop", "contact", "steering", "mouse-position", "buttons", "ping", "picture-mode", "shutdown"};

// Seed 002 table 1: data bytes per id.
constexpr std::array<std::size_t, 8> kDataLength = {0, 0, 2, 2, 1, 0, 1, 0};

std::string bytesWord(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " data byte" : " data bytes");
}

std::string idText(std::uint8_t id) {
  if (id <= id::kLastUsed)
    return "instruction " + std::to_string(id) + " (" + std::string(kNames[id]) + ")";
  return "instruction " + std::to_string(id);
}

DecodeError error(DecodeError::Kind kind, std::uint8_t id, std::size_t expected = 0,
                  std::size_t received = 0) {
  DecodeError e;
  e.kind = kind;
  e.id = id;
  e.expected = expected;
  e.received = received;
  return e;
}

DecodeError outOfRange(std::uint8_t id, std::string field, int value) {
  DecodeError e = error(DecodeError::Kind::OutOfRange, id);
  e.field = std::move(field);
  e.value = value;
  return e;
}

}  // namespace

std::string_view buttonName(Button b) {
  switch (b) {
    case Button::Manual:
      return "manual";
    case Button::Automatic:
      return "automatic";
    case Button::SensitivityUp:
      return "sensitivity-up";
    case Button::SensitivityDown:
      return "sensitivity-down";
  }
  return "?";
}

std::optional<Button> buttonFromName(std::string_view name) {
  for (Button b : kButtons)
    if (buttonName(b) == name) return b;
  return std::nullopt;
}

std::string_view pictureName(Picture p) {
  switch (p) {
    case Picture::Rgb:
      return "rgb";
    case Picture::Hsv:
      return "hsv";
    case Picture::Filter:
      return "filter";
  }
  return "?";
}

std::optional<Picture> pictureFromName(std::string_view name) {
  for (Picture p : {Picture::Rgb, Picture::Hsv, Picture::Filter})
    if (pictureName(p) == name) return p;
  return std::nullopt;
}

std::string DecodeError::message() const {
  switch (kind) {
    case Kind::Empty:
      return "empty instruction: no header byte";
    case Kind::UnusedId:
      return idText(id) + " is unused (ids 8-15 stop the robot; used ids are 0-7), with " +
             bytesWord(received);
    case Kind::LengthMismatch:
      return idText(id) + ": the header announces " + bytesWord(expected) + " but " +
             std::to_string(received) + " followed";
    case Kind::WrongLength:
      return idText(id) + " takes " + bytesWord(expected) + ", the header announces " +
             std::to_string(received);
    case Kind::OutOfRange: {
      const std::string what = idText(id) + ": " + field;
      if (field == "x") return pitwall::outOfRange(what, value, kClickMinX, kClickMaxX);
      if (field == "y") return pitwall::outOfRange(what, value, kClickMinY, kClickMaxY);
      if (field == "mode")
        return pitwall::outOfRange(what, value, 0, 2) + " (0 rgb, 1 hsv, 2 filter)";
      return what + " " + std::to_string(value) + " is out of range";
    }
    case Kind::NotAnAnswer:
      return "robot answer " + hexByte(value) + (received == 1 ? "" : " (and more)") +
             " is not the contact answer 0x4b (K), the only byte the robot sends";
  }
  return "malformed instruction";
}

std::optional<std::size_t> dataLength(std::uint8_t id) {
  if (id > id::kLastUsed) return std::nullopt;
  return kDataLength[id];
}

Result<Instruction, DecodeError> decode(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return Unexpected{error(DecodeError::Kind::Empty, 0)};
  const std::uint8_t header = bytes[0];
  const auto id = static_cast<std::uint8_t>(header >> 4);
  const std::size_t announced = header & 0x0f;
  const std::size_t received = bytes.size() - 1;
  if (announced != received)
    return Unexpected{error(DecodeError::Kind::LengthMismatch, id, announced, received)};
  if (id > id::kLastUsed) return Unexpected{error(DecodeError::Kind::UnusedId, id, 0, received)};
  if (announced != kDataLength[id])
    return Unexpected{error(DecodeError::Kind::WrongLength, id, kDataLength[id], announced)};
  const auto* d = bytes.data() + 1;
  switch (id) {
    case id::kStop:
      return Instruction{Stop{}};
    case id::kContact:
      return Instruction{Contact{}};
    case id::kSteering:
      return Instruction{Steering{static_cast<std::int8_t>(d[0]), static_cast<std::int8_t>(d[1])}};
    case id::kMousePosition:
      if (d[0] < kClickMinX || d[0] > kClickMaxX) return Unexpected{outOfRange(id, "x", d[0])};
      if (d[1] < kClickMinY || d[1] > kClickMaxY) return Unexpected{outOfRange(id, "y", d[1])};
      return Instruction{MousePosition{d[0], d[1]}};
    case id::kButtons:
      return Instruction{Buttons{d[0]}};
    case id::kPing:
      return Instruction{Ping{}};
    case id::kPictureMode:
      if (d[0] > 2) return Unexpected{outOfRange(id, "mode", d[0])};
      return Instruction{PictureMode{static_cast<Picture>(d[0])}};
    default:
      return Instruction{Shutdown{}};
  }
}

Frame encode(const Instruction& instruction) {
  Frame f;
  const auto id = instructionId(instruction);
  auto put = [&f](std::uint8_t b) { f.bytes[f.length++] = b; };
  put(static_cast<std::uint8_t>(id << 4 | kDataLength[id]));
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, Steering>) {
          put(static_cast<std::uint8_t>(m.x));
          put(static_cast<std::uint8_t>(m.y));
        } else if constexpr (std::is_same_v<T, MousePosition>) {
          put(m.x);
          put(m.y);
        } else if constexpr (std::is_same_v<T, Buttons>) {
          put(m.raw);
        } else if constexpr (std::is_same_v<T, PictureMode>) {
          put(static_cast<std::uint8_t>(m.mode));
        }
      },
      instruction);
  return f;
}

Result<bool, DecodeError> decodeAnswer(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) {
    DecodeError e = error(DecodeError::Kind::Empty, 0);
    return Unexpected{e};
  }
  if (bytes.size() != 1 || bytes[0] != kContactAnswer) {
    DecodeError e = error(DecodeError::Kind::NotAnAnswer, 0, 1, bytes.size());
    e.value = bytes[0];
    return Unexpected{e};
  }
  return true;
}

std::string_view name(const Instruction& instruction) {
  return kNames[instruction.index()];
}

std::uint8_t instructionId(const Instruction& instruction) {
  return static_cast<std::uint8_t>(instruction.index());
}

std::optional<std::string> validate(const Instruction& instruction) {
  if (const auto* c = std::get_if<MousePosition>(&instruction)) {
    if (auto e = pitwall::checkRange("click x", c->x, kClickMinX, kClickMaxX)) return e;
    if (auto e = pitwall::checkRange("click y", c->y, kClickMinY, kClickMaxY)) return e;
  }
  if (const auto* p = std::get_if<PictureMode>(&instruction)) {
    if (static_cast<int>(p->mode) > 2)
      return pitwall::outOfRange("picture mode", static_cast<int>(p->mode), 0, 2) +
             " (rgb, hsv, filter)";
  }
  return std::nullopt;
}

std::vector<Result<Instruction, DecodeError>> StreamDecoder::feed(
    std::span<const std::uint8_t> bytes) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  std::vector<Result<Instruction, DecodeError>> out;
  std::size_t at = 0;
  while (at < buffer_.size()) {
    const std::size_t size = 1 + (buffer_[at] & 0x0f);
    if (buffer_.size() - at < size) break;
    out.push_back(decode(std::span<const std::uint8_t>(buffer_.data() + at, size)));
    at += size;
  }
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(at));
  return out;
}

}  // namespace pitwall::mindroad
