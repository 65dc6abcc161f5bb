#include "engine/protocol/alphabot/ble_codec.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

#include "engine/core/overload.hpp"
#include "engine/protocol/alphabot/message_json.hpp"

namespace pitwall::alphabot::ble {

namespace {

using Bytes = std::vector<std::uint8_t>;
using In = std::span<const std::uint8_t>;

constexpr std::array<CharacteristicInfo, 8> kCharacteristics{{
    {Characteristic::DriveSteer, "DRIVE_STEER", kDriveSteerUuid, 2, true, false},
    {Characteristic::Sensor, "SENSOR", kSensorUuid, 5, true, true},
    {Characteristic::Toggle, "TOGGLE", kToggleUuid, 2, true, true},
    {Characteristic::Obstacle, "OBSTACLE", kObstacleUuid, 7, true, true},
    {Characteristic::PingClient, "PINGCLIENT", kPingClientUuid, 1, false, true},
    {Characteristic::Calibrate, "CALIBRATE", kCalibrateUuid, 1, true, true},
    {Characteristic::TargetNavi, "TARGET_NAVI", kTargetNaviUuid, 4, true, false},
    {Characteristic::PathFinding, "PATH_FINDING", kPathFindingUuid, kPathFindingSize, false, false},
}};

constexpr int kMaxDegree = 359;  // a degree travels in 9 bits (§3 sensor), 0–359 in use
constexpr std::uint8_t kMaxAnchorId = 15;  // the anchor id is the SENSOR byte's bits 3–0

std::string nameOf(Characteristic c) {
  return info(c).name;
}

Unexpected<BleCodecError> error(Characteristic c, const std::string& what) {
  return Unexpected(BleCodecError{c, nameOf(c) + ": " + what});
}

std::string bytesText(std::size_t n) {
  return std::to_string(n) + (n == 1 ? " byte" : " bytes");
}

void put16(Bytes& out, std::int16_t v) {
  auto u = static_cast<std::uint16_t>(v);
  out.push_back(static_cast<std::uint8_t>(u & 0xff));
  out.push_back(static_cast<std::uint8_t>(u >> 8));
}

std::int16_t get16(In in, std::size_t at) {
  return static_cast<std::int16_t>(in[at] | (in[at + 1] << 8));
}

void padTo(Bytes& out, std::size_t size) {
  if (out.size() < size) out.resize(size, 0);
}

// The SENSOR control byte: the answer bit, the kind in bits 6–4, the low nibble.
std::uint8_t control(bool answer, SensorKind kind, std::uint8_t low) {
  return static_cast<std::uint8_t>((answer ? kSensorAnswerBit : 0) |
                                   (static_cast<std::uint8_t>(kind) << 4) | (low & 0x0f));
}

std::optional<BleCodecError> checkDegree(Characteristic c, int degree) {
  if (degree >= 0 && degree <= kMaxDegree) return std::nullopt;
  return BleCodecError{c, nameOf(c) + ": degree " + std::to_string(degree) +
                              " is outside 0–359 (the 9-bit degree field)"};
}

std::optional<BleCodecError> checkByte(Characteristic c, const char* what, int value) {
  if (value >= 0 && value <= 255) return std::nullopt;
  return BleCodecError{c, nameOf(c) + ": " + what + " " + std::to_string(value) +
                              " does not fit in the one byte BLE gives it (0–255)"};
}

std::optional<BleCodecError> checkAnchor(Characteristic c, int id) {
  if (id >= 0 && id <= kMaxAnchorId) return std::nullopt;
  return BleCodecError{c, nameOf(c) + ": anchor id " + std::to_string(id) +
                              " does not fit in the SENSOR byte's 4 bits (0–15)"};
}

// Distance request/answer: bit 8 of the degree in the control byte, bits 0–7 in the next.
Bytes distanceBytes(bool answer, int degree, std::uint8_t distance) {
  Bytes out{control(answer, SensorKind::Distance, static_cast<std::uint8_t>((degree >> 8) & 1)),
            static_cast<std::uint8_t>(degree & 0xff), distance};
  padTo(out, 5);
  return out;
}

Bytes xyBytes(Bytes out, std::int16_t x, std::int16_t y) {
  put16(out, x);
  put16(out, y);
  return out;
}

BleValue value(Characteristic c, Bytes bytes) {
  return BleValue{c, std::move(bytes)};
}

// ---- lengths ----

std::optional<BleCodecError> exactly(Characteristic c, In in, std::size_t n) {
  if (in.size() == n) return std::nullopt;
  return BleCodecError{c,
                       nameOf(c) + ": " + bytesText(in.size()) + ", expected " + std::to_string(n)};
}

// OBSTACLE: each sub-command needs `need` bytes; the value may be padded up to the
// characteristic's size (7; 8 for "registered", whose fields need 8).
std::optional<BleCodecError> obstacleLength(In in, std::size_t need, const char* sub) {
  std::size_t most = std::max<std::size_t>(need, info(Characteristic::Obstacle).size);
  if (in.size() >= need && in.size() <= most) return std::nullopt;
  return BleCodecError{Characteristic::Obstacle,
                       std::string("OBSTACLE: ") + sub + " has " + bytesText(in.size()) +
                           ", expected " +
                           (need == most ? std::to_string(need)
                                         : std::to_string(need) + "–" + std::to_string(most))};
}

const char* kindName(std::uint8_t kind) {
  switch (kind) {
    case 0:
      return "distance";
    case 1:
      return "compass";
    case 2:
      return "map size";
    case 3:
      return "positioning";
    case 4:
      return "positioning anchor";
  }
  return "unknown";
}

// The low nibble of kinds that have no parameter there must be zero.
std::optional<BleCodecError> lowNibbleZero(std::uint8_t b0, std::uint8_t kind) {
  if ((b0 & 0x0f) == 0) return std::nullopt;
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%x", b0 & 0x0f);
  return BleCodecError{Characteristic::Sensor, std::string("SENSOR: bits 3–0 must be 0 for kind ") +
                                                   kindName(kind) + ", got " + buf};
}

// The SENSOR value's control byte, checked (5 bytes, the answer bit as expected): the kind.
Result<std::uint8_t, BleCodecError> sensorKind(In in, bool answer) {
  constexpr Characteristic c = Characteristic::Sensor;
  if (auto e = exactly(c, in, 5)) return Unexpected(*e);
  if (((in[0] & kSensorAnswerBit) != 0) != answer)
    return error(c, answer ? "bit 7 is clear: a client's request, not the robot's answer"
                           : "bit 7 is set: the robot's answer, not a client's request");
  return static_cast<std::uint8_t>((in[0] >> 4) & 0x07);
}

// The 9-bit degree of a distance request or answer: bit 8 in the control byte, bits 0–7 next.
Result<std::int16_t, BleCodecError> sensorDegree(In in) {
  constexpr Characteristic c = Characteristic::Sensor;
  if (in[0] & 0x0e)
    return error(c, "bits 3–1 of a distance value must be 0 (bit 0 is degree bit 8)");
  int degree = ((in[0] & 1) << 8) | in[1];
  if (auto e = checkDegree(c, degree)) return Unexpected(*e);
  return static_cast<std::int16_t>(degree);
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char ch) {
    return static_cast<char>(ch == '-' ? '_' : std::tolower(ch));
  });
  return out;
}

}  // namespace

const std::array<CharacteristicInfo, 8>& characteristics() {
  return kCharacteristics;
}

const CharacteristicInfo& info(Characteristic c) {
  return kCharacteristics[static_cast<std::size_t>(c)];
}

std::optional<Characteristic> characteristicByUuid(std::string_view uuid) {
  std::string u(uuid);
  std::transform(u.begin(), u.end(), u.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  for (const auto& i : kCharacteristics)
    if (u == i.uuid) return i.id;
  return std::nullopt;
}

std::optional<Characteristic> characteristicNamed(std::string_view nameOrUuid) {
  if (auto byUuid = characteristicByUuid(nameOrUuid)) return byUuid;
  std::string n = lower(nameOrUuid);
  for (const auto& i : kCharacteristics)
    if (n == lower(i.name)) return i.id;
  return std::nullopt;
}

// ---- encoding ----

Result<BleValue, BleCodecError> encode(const Request& request) {
  using R = Result<BleValue, BleCodecError>;
  return std::visit(
      Overload{
          [](const Drive& m) -> R {
            // steer first, then speed (§2; WLAN 0x01 has them the other way round)
            return value(Characteristic::DriveSteer,
                         {static_cast<std::uint8_t>(m.steer), static_cast<std::uint8_t>(m.speed)});
          },
          [](const MeasureDistance& m) -> R {
            if (auto e = checkDegree(Characteristic::Sensor, m.degree)) return Unexpected(*e);
            return value(Characteristic::Sensor, distanceBytes(false, m.degree, 0));
          },
          [](const CalibrateSteering&) -> R { return value(Characteristic::Calibrate, {1}); },
          [](const CalibrateCompass&) -> R { return value(Characteristic::Calibrate, {2}); },
          [](const SetToggles& m) -> R {
            return value(Characteristic::Toggle, {m.toggles.settings, m.toggles.logging});
          },
          [](const Ping&) -> R {
            return error(Characteristic::PingClient,
                         "a ping has no BLE write; over BLE a ping is a read of PINGCLIENT, "
                         "timed by the link (docs/robots.md)");
          },
          [](const SetAnchor& m) -> R {
            if (auto e = checkAnchor(Characteristic::Sensor, m.id)) return Unexpected(*e);
            return value(Characteristic::Sensor,
                         xyBytes({control(false, SensorKind::Anchor, m.id)}, m.x, m.y));
          },
          [](const NavigateTo& m) -> R {
            return value(Characteristic::TargetNavi, xyBytes({}, m.x, m.y));
          },
          [](const AddObstacle& m) -> R {
            if (auto e = checkByte(Characteristic::Obstacle, "width", m.width))
              return Unexpected(*e);
            if (auto e = checkByte(Characteristic::Obstacle, "height", m.height))
              return Unexpected(*e);
            auto out = xyBytes({1}, m.x, m.y);
            out.push_back(static_cast<std::uint8_t>(m.width));
            out.push_back(static_cast<std::uint8_t>(m.height));
            return value(Characteristic::Obstacle, std::move(out));
          },
          [](const RemoveObstacleById& m) -> R {
            if (m.id == kRemoveByPosition)
              return error(Characteristic::Obstacle,
                           "obstacle id 255 cannot be removed by id: 0xFF marks a removal by "
                           "position on BLE");
            return value(Characteristic::Obstacle, {3, 0, 0, 0, 0, m.id});
          },
          [](const RemoveObstacleAt& m) -> R {
            auto out = xyBytes({3}, m.x, m.y);
            out.push_back(kRemoveByPosition);
            return value(Characteristic::Obstacle, std::move(out));
          },
          [](const ClearObstacles&) -> R { return value(Characteristic::Obstacle, {4}); },
      },
      request);
}

Result<BleValue, BleCodecError> encode(const SensorQuery& query) {
  if (query.kind == SensorKind::Distance)
    return error(Characteristic::Sensor, "a distance request needs a degree (MeasureDistance)");
  if (query.kind == SensorKind::Anchor)
    return error(Characteristic::Sensor,
                 "a positioning-anchor request carries the anchor (SetAnchor)");
  Bytes out{control(false, query.kind, 0)};
  padTo(out, 5);
  return value(Characteristic::Sensor, std::move(out));
}

Result<BleValue, BleCodecError> encode(const Response& response) {
  using R = Result<BleValue, BleCodecError>;
  auto sensor = [](Bytes out) {
    padTo(out, 5);
    return value(Characteristic::Sensor, std::move(out));
  };
  return std::visit(
      Overload{
          [](const Distance& m) -> R {
            if (auto e = checkDegree(Characteristic::Sensor, m.degree)) return Unexpected(*e);
            if (auto e = checkByte(Characteristic::Sensor, "distance", m.distance))
              return Unexpected(*e);
            return value(Characteristic::Sensor,
                         distanceBytes(true, m.degree, static_cast<std::uint8_t>(m.distance)));
          },
          [&](const Position& m) -> R {
            return sensor(xyBytes({control(true, SensorKind::Positioning, 0)}, m.x, m.y));
          },
          [](const Path& m) -> R {
            if (m.waypoints.size() > kMaxBleWaypoints)
              return error(Characteristic::PathFinding,
                           std::to_string(m.waypoints.size()) +
                               " waypoints do not fit in 20 bytes (at most 4)");
            Bytes out{static_cast<std::uint8_t>(m.waypoints.size())};
            for (const auto& w : m.waypoints) out = xyBytes(std::move(out), w.x, w.y);
            padTo(out, kPathFindingSize);
            return value(Characteristic::PathFinding, std::move(out));
          },
          [&](const Compass& m) -> R {
            Bytes out{control(true, SensorKind::Compass, 0)};
            put16(out, m.degree);
            return sensor(std::move(out));
          },
          [](const PingReply&) -> R {
            return error(Characteristic::PingClient,
                         "a ping reply has no BLE form: the PINGCLIENT read is the answer");
          },
          [](const ObstacleRegistered& m) -> R {
            if (auto e = checkByte(Characteristic::Obstacle, "width", m.width))
              return Unexpected(*e);
            if (auto e = checkByte(Characteristic::Obstacle, "height", m.height))
              return Unexpected(*e);
            auto out = xyBytes({2, m.id}, m.x, m.y);
            out.push_back(static_cast<std::uint8_t>(m.width));
            out.push_back(static_cast<std::uint8_t>(m.height));
            return value(Characteristic::Obstacle, std::move(out));
          },
          [&](const MapSize& m) -> R {
            return sensor({control(true, SensorKind::MapSize, 0), m.length, m.width});
          },
          [&](const AnchorPosition& m) -> R {
            if (auto e = checkAnchor(Characteristic::Sensor, m.id)) return Unexpected(*e);
            return sensor(xyBytes({control(true, SensorKind::Anchor, m.id)}, m.x, m.y));
          },
          [](const CalibrationFinished&) -> R { return value(Characteristic::Calibrate, {0}); },
      },
      response);
}

BleValue encode(const TogglesReport& report) {
  return value(Characteristic::Toggle, {report.toggles.settings, report.toggles.logging});
}

BleValue encode(const Heartbeat& heartbeat) {
  return value(Characteristic::PingClient, {heartbeat.value});
}

BleValue encode(const PathPending&) {
  Bytes out{kPathPending};
  padTo(out, kPathFindingSize);
  return value(Characteristic::PathFinding, std::move(out));
}

// ---- decoding: what a client wrote ----

Result<ClientMessage, BleCodecError> decodeRequest(Characteristic c, In in) {
  using R = Result<ClientMessage, BleCodecError>;
  auto request = [](Request r) -> R { return ClientMessage(std::move(r)); };
  switch (c) {
    case Characteristic::DriveSteer:
      if (auto e = exactly(c, in, 2)) return Unexpected(*e);
      return request(Drive{static_cast<std::int8_t>(in[1]), static_cast<std::int8_t>(in[0])});
    case Characteristic::Sensor: {
      auto head = sensorKind(in, false);
      if (!head) return Unexpected(head.error());
      std::uint8_t kind = *head;
      switch (kind) {
        case 0: {
          auto degree = sensorDegree(in);
          if (!degree) return Unexpected(degree.error());
          return request(MeasureDistance{*degree});
        }
        case 1:
        case 2:
        case 3:
          if (auto e = lowNibbleZero(in[0], kind)) return Unexpected(*e);
          return ClientMessage(SensorQuery{static_cast<SensorKind>(kind)});
        case 4:
          return request(
              SetAnchor{static_cast<std::uint8_t>(in[0] & 0x0f), get16(in, 1), get16(in, 3)});
      }
      return error(c, "unknown sensor kind " + std::to_string(kind) + " (bits 6–4; 0–4 are used)");
    }
    case Characteristic::Toggle:
      if (auto e = exactly(c, in, 2)) return Unexpected(*e);
      return request(SetToggles{Toggles{in[0], in[1]}});
    case Characteristic::Obstacle: {
      if (in.empty()) return error(c, "0 bytes, expected a sub-command (1, 3 or 4) and its data");
      switch (in[0]) {
        case 1:
          if (auto e = obstacleLength(in, 7, "add (1)")) return Unexpected(*e);
          return request(AddObstacle{get16(in, 1), get16(in, 3), in[5], in[6]});
        case 3:
          if (auto e = obstacleLength(in, 6, "remove one (3)")) return Unexpected(*e);
          if (in[5] == kRemoveByPosition)
            return request(RemoveObstacleAt{get16(in, 1), get16(in, 3)});
          return request(RemoveObstacleById{in[5]});
        case 4:
          if (auto e = obstacleLength(in, 1, "remove all (4)")) return Unexpected(*e);
          return request(ClearObstacles{});
        case 2:
          return error(c, "sub-command 2 (registered) is the robot's answer, not a request");
      }
      return error(c, "unknown sub-command " + std::to_string(in[0]) +
                          " (1 add, 3 remove one, "
                          "4 remove all)");
    }
    case Characteristic::PingClient:
      return error(c, "read/notify only: a client does not write it");
    case Characteristic::Calibrate:
      if (auto e = exactly(c, in, 1)) return Unexpected(*e);
      if (in[0] == 1) return request(CalibrateSteering{});
      if (in[0] == 2) return request(CalibrateCompass{});
      if (in[0] == 0) return error(c, "0 (calibration finished) is the robot's answer");
      return error(c, "unknown value " + std::to_string(in[0]) +
                          " (1 calibrate steering, 2 calibrate compass)");
    case Characteristic::TargetNavi:
      if (auto e = exactly(c, in, 4)) return Unexpected(*e);
      return request(NavigateTo{get16(in, 0), get16(in, 2)});
    case Characteristic::PathFinding:
      return error(c, "read only: a client does not write it");
  }
  return error(c, "unknown characteristic");
}

// ---- decoding: what a robot sent ----

Result<RobotMessage, BleCodecError> decodeResponse(Characteristic c, In in) {
  using R = Result<RobotMessage, BleCodecError>;
  auto response = [](Response r) -> R { return RobotMessage(std::move(r)); };
  switch (c) {
    case Characteristic::Sensor: {
      auto head = sensorKind(in, true);
      if (!head) return Unexpected(head.error());
      std::uint8_t kind = *head;
      switch (kind) {
        case 0: {
          auto degree = sensorDegree(in);
          if (!degree) return Unexpected(degree.error());
          return response(Distance{*degree, in[2]});
        }
        case 1:
          if (auto e = lowNibbleZero(in[0], kind)) return Unexpected(*e);
          return response(Compass{get16(in, 1)});
        case 2:
          if (auto e = lowNibbleZero(in[0], kind)) return Unexpected(*e);
          return response(MapSize{in[1], in[2]});
        case 3:
          if (auto e = lowNibbleZero(in[0], kind)) return Unexpected(*e);
          return response(Position{get16(in, 1), get16(in, 3)});
        case 4:
          return response(
              AnchorPosition{static_cast<std::uint8_t>(in[0] & 0x0f), get16(in, 1), get16(in, 3)});
      }
      return error(c, "unknown sensor kind " + std::to_string(kind) + " (bits 6–4; 0–4 are used)");
    }
    case Characteristic::Toggle:
      if (auto e = exactly(c, in, 2)) return Unexpected(*e);
      return RobotMessage(TogglesReport{Toggles{in[0], in[1]}});
    case Characteristic::Obstacle:
      if (in.empty()) return error(c, "0 bytes, expected sub-command 2 (registered) and its data");
      if (in[0] != 2)
        return error(c, "sub-command " + std::to_string(in[0]) +
                            " is not an answer: a robot sends 2 (registered)");
      if (auto e = obstacleLength(in, 8, "registered (2)")) return Unexpected(*e);
      return response(ObstacleRegistered{in[1], get16(in, 2), get16(in, 4), in[6], in[7]});
    case Characteristic::PingClient:
      if (auto e = exactly(c, in, 1)) return Unexpected(*e);
      return RobotMessage(Heartbeat{in[0]});
    case Characteristic::Calibrate:
      if (auto e = exactly(c, in, 1)) return Unexpected(*e);
      if (in[0] == 0) return response(CalibrationFinished{});
      return error(c, "value " + std::to_string(in[0]) +
                          " is not an answer: a robot notifies 0 (calibration finished)");
    case Characteristic::PathFinding: {
      if (in.empty() || in.size() > kPathFindingSize)
        return error(c, bytesText(in.size()) + ", expected 1–20");
      if (in[0] == kPathPending) return RobotMessage(PathPending{});
      std::size_t count = in[0];
      if (count > kMaxBleWaypoints)
        return error(c, "count " + std::to_string(count) + " is more than 4 waypoints");
      if (in.size() < 1 + 4 * count)
        return error(c, bytesText(in.size()) + " for " + std::to_string(count) +
                            " waypoints, expected at least " + std::to_string(1 + 4 * count));
      Path path;
      for (std::size_t i = 0; i < count; ++i)
        path.waypoints.push_back(Waypoint{get16(in, 1 + 4 * i), get16(in, 3 + 4 * i)});
      return response(std::move(path));
    }
    case Characteristic::DriveSteer:
    case Characteristic::TargetNavi:
      return error(c, "written by the client, never notified by the robot");
  }
  return error(c, "unknown characteristic");
}

// ---- JSON for the command line ----

namespace {

// The shared JSON of the messages (message_json.hpp), without the WLAN packet id.
nlohmann::json shared(nlohmann::json j) {
  j.erase("packet");
  return j;
}

nlohmann::json requestJson(const ClientMessage& m) {
  return std::visit(Overload{
                        [](const SensorQuery& q) -> nlohmann::json {
                          return {{"name", "sensor-query"},
                                  {"kind", kindName(static_cast<std::uint8_t>(q.kind))}};
                        },
                        [](const Request& r) { return shared(toJson(r)); },
                    },
                    m);
}

nlohmann::json responseJson(const RobotMessage& m) {
  return std::visit(Overload{
                        [](const TogglesReport& t) -> nlohmann::json {
                          return {{"name", "toggles"}, {"toggles", toJson(t.toggles)}};
                        },
                        [](const Heartbeat& h) -> nlohmann::json {
                          return {{"name", "heartbeat"}, {"value", h.value}};
                        },
                        [](const PathPending&) -> nlohmann::json {
                          return {{"name", "path-pending"}};
                        },
                        [](const Response& r) { return shared(toJson(r)); },
                    },
                    m);
}

// Which way the bytes travel, from what they say (see decodeBle in the header).
bool fromRobot(Characteristic c, In in) {
  switch (c) {
    case Characteristic::Sensor:
      return !in.empty() && (in[0] & kSensorAnswerBit);
    case Characteristic::Obstacle:
      return !in.empty() && in[0] == 2;
    case Characteristic::Calibrate:
      return !in.empty() && in[0] == 0;
    case Characteristic::PingClient:
    case Characteristic::PathFinding:
      return true;
    default:
      return false;
  }
}

}  // namespace

}  // namespace pitwall::alphabot::ble

namespace pitwall::alphabot {

using namespace ble;

Result<nlohmann::json, std::string> decodeBle(std::string_view characteristic,
                                              std::span<const std::uint8_t> bytes) {
  auto c = characteristicNamed(characteristic);
  if (!c) {
    std::string known;
    for (const auto& i : kCharacteristics)
      known += (known.empty() ? "" : ", ") + std::string(i.name);
    return Unexpected(std::string("'") + std::string(characteristic) +
                      "' is not an Alphabot BLE characteristic (one of " + known +
                      ", or its UUID)");
  }
  nlohmann::json j;
  if (fromRobot(*c, bytes)) {
    auto r = decodeResponse(*c, bytes);
    if (!r) return Unexpected(r.error().message);
    j = responseJson(*r);
    j["direction"] = "response";
  } else {
    auto r = decodeRequest(*c, bytes);
    if (!r) return Unexpected(r.error().message);
    j = requestJson(*r);
    j["direction"] = "request";
  }
  j["characteristic"] = info(*c).name;
  j["uuid"] = info(*c).uuid;
  return j;
}

}  // namespace pitwall::alphabot
