#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "engine/core/hex.hpp"
#include "engine/core/overload.hpp"

#include <cstdio>

namespace pitwall::alphabot::wlan {
namespace {

struct Writer {
  Options options;
  Bytes out;
  void u8(std::uint8_t v) { out.push_back(v); }
  void unsignedN(std::uint64_t v, int n) {
    std::size_t at = out.size();
    out.resize(at + static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      int shift = options.order == ByteOrder::Little ? 8 * i : 8 * (n - 1 - i);
      out[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> shift);
    }
  }
  void i8(std::int8_t v) { u8(static_cast<std::uint8_t>(v)); }
  void i16(std::int16_t v) { unsignedN(static_cast<std::uint16_t>(v), 2); }
  void u16(std::uint16_t v) { unsignedN(v, 2); }
  void i64(std::int64_t v) { unsignedN(static_cast<std::uint64_t>(v), 8); }
};

// Reads fields of a packet whose length was checked before.
struct Reader {
  Options options;
  std::span<const std::uint8_t> in;
  std::size_t at = 1;  // after the id
  std::uint64_t unsignedN(int n) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) {
      int shift = options.order == ByteOrder::Little ? 8 * i : 8 * (n - 1 - i);
      v |= static_cast<std::uint64_t>(in[at + static_cast<std::size_t>(i)]) << shift;
    }
    at += static_cast<std::size_t>(n);
    return v;
  }
  std::uint8_t u8() { return in[at++]; }
  std::int8_t i8() { return static_cast<std::int8_t>(u8()); }
  std::int16_t i16() { return static_cast<std::int16_t>(static_cast<std::uint16_t>(unsignedN(2))); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(unsignedN(2)); }
  std::int64_t i64() { return static_cast<std::int64_t>(unsignedN(8)); }
};

// Fixed packet lengths (id included); 0x83 is 2 + 4 × count; 0 for an unknown id.
std::size_t fixedLength(std::uint8_t id) {
  switch (id) {
    case 0x01:
      return 3;
    case 0x02:
      return 3;
    case 0x03:
      return 1;
    case 0x04:
      return 1;
    case 0x05:
      return 3;
    case kToggleAlias:
      return 3;
    case 0x06:
      return 9;
    case 0x07:
      return 6;
    case 0x08:
      return 5;
    case 0x09:
      return 9;
    case 0x0A:
      return 2;
    case 0x0B:
      return 5;
    case 0x0C:
      return 1;
    case 0x81:
      return 5;
    case 0x82:
      return 5;
    case 0x83:
      return 2;  // at least: id and count
    case 0x84:
      return 3;
    case 0x85:
      return 9;
    case 0x86:
      return 10;
    default:
      return 0;
  }
}

// The whole length of the packet at the start of `bytes`, or nullopt when the count byte of a
// path has not arrived yet. The id must be known.
std::optional<std::size_t> packetLength(std::span<const std::uint8_t> bytes) {
  std::uint8_t id = bytes[0];
  if (id != 0x83) return fixedLength(id);
  if (bytes.size() < 2) return std::nullopt;
  return 2 + 4 * static_cast<std::size_t>(bytes[1]);
}

Packet decodeKnown(std::span<const std::uint8_t> bytes, Options options) {
  Reader r{options, bytes};
  switch (bytes[0]) {
    case 0x01: {
      Drive d;
      d.speed = r.i8();
      d.steer = r.i8();
      return Request{d};
    }
    case 0x02:
      return Request{MeasureDistance{r.i16()}};
    case 0x03:
      return Request{CalibrateSteering{}};
    case 0x04:
      return Request{CalibrateCompass{}};
    case 0x05:
    case kToggleAlias: {
      SetToggles t;
      t.toggles.settings = r.u8();
      t.toggles.logging = r.u8();
      return Request{t};
    }
    case 0x06:
      return Request{Ping{r.i64()}};
    case 0x07: {
      SetAnchor a;
      a.id = r.u8();
      a.x = r.i16();
      a.y = r.i16();
      return Request{a};
    }
    case 0x08: {
      NavigateTo n;
      n.x = r.i16();
      n.y = r.i16();
      return Request{n};
    }
    case 0x09: {
      AddObstacle o;
      o.x = r.i16();
      o.y = r.i16();
      o.width = r.u16();
      o.height = r.u16();
      return Request{o};
    }
    case 0x0A:
      return Request{RemoveObstacleById{r.u8()}};
    case 0x0B: {
      RemoveObstacleAt o;
      o.x = r.i16();
      o.y = r.i16();
      return Request{o};
    }
    case 0x0C:
      return Request{ClearObstacles{}};
    case 0x81: {
      Distance d;
      d.degree = r.i16();
      d.distance = r.u16();
      return Response{d};
    }
    case 0x82: {
      Position p;
      p.x = r.i16();
      p.y = r.i16();
      return Response{p};
    }
    case 0x83: {
      Path p;
      std::uint8_t count = r.u8();
      p.waypoints.reserve(count);
      for (int i = 0; i < count; ++i) {
        Waypoint w;
        w.x = r.i16();
        w.y = r.i16();
        p.waypoints.push_back(w);
      }
      return Response{p};
    }
    case 0x84:
      return Response{Compass{r.i16()}};
    case 0x85:
      return Response{PingReply{r.i64()}};
    default: {  // 0x86
      ObstacleRegistered o;
      o.id = r.u8();
      o.x = r.i16();
      o.y = r.i16();
      o.width = r.u16();
      o.height = r.u16();
      return Response{o};
    }
  }
}

}  // namespace

std::string DecodeError::message() const {
  std::string n(nameOfId(id));
  std::string what = "packet " + hexByte(id) + (n.empty() ? "" : " (" + n + ")");
  switch (kind) {
    case Kind::Empty:
      return "empty packet: no id byte";
    case Kind::UnknownId:
      return "unknown packet id " + hexByte(id) + " (known: requests 0x01..0x0c and 0xc0, " +
             "responses 0x81..0x86): " + std::to_string(received) + " byte(s) not decoded";
    case Kind::WrongDirection:
      return what + " travels the other way (" +
             (isRequestId(id) ? "a request, where responses are expected"
                              : "a response, where requests are expected") +
             "): " + std::to_string(received) + " byte(s) not decoded";
    case Kind::TooShort:
      return what + " is " + std::to_string(received) + " byte(s), expected " +
             std::to_string(expected) + (id == 0x83 && received >= 2 ? " (from its count)" : "");
    case Kind::TooLong:
      return what + " is " + std::to_string(received) + " byte(s), expected " +
             std::to_string(expected) + (id == 0x83 ? " (from its count)" : "");
  }
  return "malformed packet";
}

bool isRequestId(std::uint8_t id) {
  return (id >= 0x01 && id <= 0x0C) || id == kToggleAlias;
}
bool isResponseId(std::uint8_t id) {
  return id >= 0x81 && id <= 0x86;
}

std::string_view nameOfId(std::uint8_t id) {
  switch (id) {
    case 0x01:
      return "drive";
    case 0x02:
      return "measure-distance";
    case 0x03:
      return "calibrate-steering";
    case 0x04:
      return "calibrate-compass";
    case 0x05:
    case kToggleAlias:
      return "toggles";
    case 0x06:
      return "ping";
    case 0x07:
      return "anchor";
    case 0x08:
      return "navigate";
    case 0x09:
      return "add-obstacle";
    case 0x0A:
      return "remove-obstacle";
    case 0x0B:
      return "remove-obstacle-at";
    case 0x0C:
      return "clear-obstacles";
    case 0x81:
      return "distance";
    case 0x82:
      return "position";
    case 0x83:
      return "path";
    case 0x84:
      return "compass";
    case 0x85:
      return "ping-reply";
    case 0x86:
      return "obstacle-registered";
    default:
      return "";
  }
}

std::uint8_t packetId(const Request& request) {
  return static_cast<std::uint8_t>(request.index() + 1);  // the variant follows 0x01..0x0C
}

std::uint8_t packetId(const Response& response) {
  // Distance..ObstacleRegistered are 0x81..0x86; the BLE-only ones have no WLAN id (0).
  return response.index() < 6 ? static_cast<std::uint8_t>(0x81 + response.index()) : 0;
}

std::string_view name(const Request& request) {
  return nameOfId(packetId(request));
}

std::string_view name(const Response& response) {
  return std::visit(
      Overload{
          [](const MapSize&) -> std::string_view { return "map-size"; },
          [](const AnchorPosition&) -> std::string_view { return "anchor-position"; },
          [](const CalibrationFinished&) -> std::string_view { return "calibration-finished"; },
          [&](const auto&) { return nameOfId(packetId(response)); }},
      response);
}

Bytes encode(const Request& request, Options options) {
  Writer w{options, {}};
  w.u8(packetId(request));
  std::visit(Overload{[&](const Drive& d) {
                        w.i8(d.speed);
                        w.i8(d.steer);
                      },
                      [&](const MeasureDistance& m) { w.i16(m.degree); },
                      [&](const CalibrateSteering&) {}, [&](const CalibrateCompass&) {},
                      [&](const SetToggles& t) {
                        w.u8(t.toggles.settings);
                        w.u8(t.toggles.logging);
                      },
                      [&](const Ping& p) { w.i64(p.time); },
                      [&](const SetAnchor& a) {
                        w.u8(a.id);
                        w.i16(a.x);
                        w.i16(a.y);
                      },
                      [&](const NavigateTo& n) {
                        w.i16(n.x);
                        w.i16(n.y);
                      },
                      [&](const AddObstacle& o) {
                        w.i16(o.x);
                        w.i16(o.y);
                        w.u16(o.width);
                        w.u16(o.height);
                      },
                      [&](const RemoveObstacleById& r) { w.u8(r.id); },
                      [&](const RemoveObstacleAt& r) {
                        w.i16(r.x);
                        w.i16(r.y);
                      },
                      [&](const ClearObstacles&) {}},
             request);
  return std::move(w.out);
}

Result<Bytes, std::string> encode(const Response& response, Options options) {
  std::uint8_t id = packetId(response);
  if (id == 0)
    return Unexpected{std::string(name(response)) +
                      " is a BLE-only answer: the WLAN protocol has no packet for it"};
  if (auto* p = std::get_if<Path>(&response); p && p->waypoints.size() > 255)
    return Unexpected{"a path packet holds at most 255 waypoints, got " +
                      std::to_string(p->waypoints.size())};
  Writer w{options, {}};
  w.u8(id);
  std::visit(Overload{[&](const Distance& d) {
                        w.i16(d.degree);
                        w.u16(d.distance);
                      },
                      [&](const Position& p) {
                        w.i16(p.x);
                        w.i16(p.y);
                      },
                      [&](const Path& p) {
                        w.u8(static_cast<std::uint8_t>(p.waypoints.size()));
                        for (const auto& wp : p.waypoints) {
                          w.i16(wp.x);
                          w.i16(wp.y);
                        }
                      },
                      [&](const Compass& c) { w.i16(c.degree); },
                      [&](const PingReply& p) { w.i64(p.time); },
                      [&](const ObstacleRegistered& o) {
                        w.u8(o.id);
                        w.i16(o.x);
                        w.i16(o.y);
                        w.u16(o.width);
                        w.u16(o.height);
                      },
                      [&](const auto&) {}},
             response);
  return std::move(w.out);
}

Result<Packet, DecodeError> decode(std::span<const std::uint8_t> bytes, Options options) {
  if (bytes.empty()) return Unexpected{DecodeError{}};
  std::uint8_t id = bytes[0];
  if (fixedLength(id) == 0)
    return Unexpected{DecodeError{DecodeError::Kind::UnknownId, id, 0, bytes.size()}};
  auto length = packetLength(bytes);
  if (!length) return Unexpected{DecodeError{DecodeError::Kind::TooShort, id, 2, bytes.size()}};
  if (bytes.size() < *length)
    return Unexpected{DecodeError{DecodeError::Kind::TooShort, id, *length, bytes.size()}};
  if (bytes.size() > *length)
    return Unexpected{DecodeError{DecodeError::Kind::TooLong, id, *length, bytes.size()}};
  return decodeKnown(bytes, options);
}

namespace {
bool accepted(std::uint8_t id, Accept accept) {
  switch (accept) {
    case Accept::Requests:
      return isRequestId(id);
    case Accept::Responses:
      return isResponseId(id);
    case Accept::Both:
      return isRequestId(id) || isResponseId(id);
  }
  return false;
}
}  // namespace

std::size_t frameLength(std::span<const std::uint8_t> pending, Accept accept) {
  if (pending.empty()) return 0;
  if (!accepted(pending[0], accept)) {
    std::size_t skip = 1;
    while (skip < pending.size() && !accepted(pending[skip], accept)) ++skip;
    return skip;
  }
  auto length = packetLength(pending);
  if (!length || pending.size() < *length) return 0;
  return *length;
}

Result<Packet, DecodeError> decodeFrame(std::span<const std::uint8_t> frame, Accept accept,
                                        Options options) {
  if (frame.empty()) return Unexpected{DecodeError{}};
  const std::uint8_t id = frame[0];
  if (!accepted(id, accept)) {
    auto kind =
        fixedLength(id) == 0 ? DecodeError::Kind::UnknownId : DecodeError::Kind::WrongDirection;
    return Unexpected{DecodeError{kind, id, 0, frame.size()}};
  }
  return decode(frame, options);
}

void StreamDecoder::feed(std::span<const std::uint8_t> bytes) {
  if (start_ > 0 && start_ == buffer_.size()) {
    buffer_.clear();
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

std::optional<Result<Packet, DecodeError>> StreamDecoder::next() {
  std::span<const std::uint8_t> rest(buffer_.data() + start_, buffer_.size() - start_);
  const std::size_t length = frameLength(rest, accept_);
  if (length == 0) return std::nullopt;
  auto packet = decodeFrame(rest.first(length), accept_, options_);
  start_ += length;
  // Keep the buffer from growing without bound on a long stream.
  if (start_ > 4096) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  return packet;
}

}  // namespace pitwall::alphabot::wlan
