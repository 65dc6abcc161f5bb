// The Alphabot's model (alphabot.hpp).
#include "engine/vehicles/alphabot.hpp"

#include "engine/core/hex.hpp"
#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/core/overload.hpp"
#include "engine/protocol/alphabot/command_text.hpp"
#include "engine/transport/gatt_link.hpp"
#include "engine/transport/socket_link.hpp"

namespace pitwall {

namespace ab = alphabot;
using ab::ble::Characteristic;

namespace {

constexpr const char* kLog = "alphabot";

std::optional<std::string> outside(const char* what, long long v, long long lo, long long hi) {
  return checkRange(what, static_cast<double>(v), static_cast<double>(lo), static_cast<double>(hi));
}

std::int16_t i16(long long v) {
  return static_cast<std::int16_t>(v);
}

}  // namespace

std::unique_ptr<Link> makeAlphabotTcpLink(Loop& loop, const std::string& host, std::uint16_t port,
                                          double connectTimeout) {
  // Every packet's length follows from its id (and 0x83's count byte) in either byte order.
  SocketLinkOptions o;
  o.host = host;
  o.port = port;
  o.peer = "the robot";
  o.connectTimeout = connectTimeout;
  o.frameLength = [](std::span<const std::uint8_t> pending) {
    return ab::wlan::frameLength(pending, ab::wlan::Accept::Responses);
  };
  return std::make_unique<SocketLink>(loop, std::move(o));
}

std::unique_ptr<Link> makeAlphabotBleLink(Loop& loop, const std::string& address,
                                          GattLinkOptions options, std::string& error) {
  GattProfile profile{"Alphabot", {}};
  for (const auto& c : ab::ble::characteristics())  // in ble::Characteristic order
    profile.characteristics.push_back({c.name, c.uuid, c.notify});
  return makeGattLink(loop, address, std::move(profile), std::move(options), error);
}

Alphabot::Alphabot(Loop& loop, std::unique_ptr<Link> link, AlphabotOptions options)
    : loop_(loop), link_(std::move(link)), options_(options) {
  link_->onFrame([this](std::span<const std::uint8_t> frame) { received(frame); });
  link_->onState([this](bool up, const std::string& reason) { linkChanged(up, reason); });
  // What close() sends, for the stop that does not need the loop (engine/core/emergency_stops.hpp)
  const ab::Request stop = ab::Drive{0, 0};
  if (options_.wire == AlphabotOptions::Wire::Wlan) {
    link_->setEmergencyStop(ab::wlan::encode(stop, options_.codec));
  } else if (auto value = ab::ble::encode(stop)) {
    link_->setEmergencyStop(
        gatt::write(static_cast<std::uint8_t>(value->characteristic), value->bytes));
  }
}

Alphabot::~Alphabot() {
  close();
  link_->onFrame(nullptr);
  link_->onState(nullptr);
}

std::string Alphabot::lastError() const {
  if (closed_) return label() + " is closed";
  if (!link_->connected()) {
    auto why = link_->refusal();
    return why.empty() ? address() + ": not connected" : why;
  }
  return bleError_;
}

void Alphabot::close() {
  if (closed_) return;
  // The link's handlers stay set (one of them may be running: a handler that calls close());
  // a closed model ignores them.
  if (link_->connected()) send(ab::Drive{0, 0});
  closed_ = true;
  if (pathTimer_) loop_.cancel(pathTimer_);
  pathTimer_ = 0;
  link_->disconnect();
}

// ---- from the robot ----

void Alphabot::linkChanged(bool up, const std::string& reason) {
  if (closed_) return;
  if (up) {
    state_.everConnected = true;
    bleError_.clear();
    pingTimes_.clear();
    log::info(kLog, label() + ": connected");
    if (auto callback = onConnection) callback(true, reason);
    return;
  }
  if (pathTimer_) loop_.cancel(pathTimer_);
  pathTimer_ = 0;
  log::warn(kLog, label() + ": " + (state_.everConnected ? "lost: " : "cannot connect: ") + reason +
                      "; retrying");
  if (auto callback = onConnection) callback(false, reason);
}

void Alphabot::malformed(const std::string& error) {
  ++state_.malformed;
  malformedWarnings_.warn(kLog, label() + ": malformed packet: " + error);
  if (auto callback = onMalformed) callback(error);
}

void Alphabot::received(std::span<const std::uint8_t> frame) {
  if (closed_) return;
  if (options_.wire == AlphabotOptions::Wire::Ble) return receivedBle(frame);
  auto packet = ab::wlan::decodeFrame(frame, ab::wlan::Accept::Responses, options_.codec);
  if (!packet) return malformed(packet.error().message());
  if (const auto* response = std::get_if<ab::Response>(&*packet)) respond(*response);
}

void Alphabot::receivedBle(std::span<const std::uint8_t> frame) {
  auto value = gatt::parse(frame);
  if (!value || value->index >= ab::ble::characteristics().size())
    return malformed("a GATT frame without a known characteristic [" + toHex(frame) + "]");
  const auto c = static_cast<Characteristic>(value->index);
  if (value->readAnswer && c == Characteristic::PingClient) {
    // Over BLE a ping is a read of PINGCLIENT: the robot's reply is the answer.
    if (pingTimes_.empty()) return;
    const auto time = pingTimes_.front();
    pingTimes_.pop_front();
    return respond(ab::PingReply{time});
  }
  auto message = ab::ble::decodeResponse(c, value->bytes);
  const bool pathRead = value->readAnswer && c == Characteristic::PathFinding;
  if (pathRead && !(message && std::holds_alternative<ab::ble::PathPending>(*message))) {
    if (pathTimer_) loop_.cancel(pathTimer_);  // an answer: no more polls
    pathTimer_ = 0;
  }
  if (!message) return malformed(message.error().message + " [" + toHex(value->bytes) + "]");
  std::visit(Overload{
                 [this](const ab::Response& r) { respond(r); },
                 [this](const ab::ble::TogglesReport& t) { state_.robotToggles = t.toggles; },
                 [this](const ab::ble::Heartbeat&) { ++state_.heartbeats; },
                 [](const ab::ble::PathPending&) {},  // the poll timer reads again
             },
             *message);
}

void Alphabot::respond(const ab::Response& response) {
  std::visit(Overload{
                 [this](const ab::Position& p) {
                   state_.x = p.x;
                   state_.y = p.y;
                 },
                 [this](const ab::Path& p) { state_.path = p.waypoints; },
                 [this](const ab::Compass& c) { state_.heading = c.degree; },
                 [this](const ab::PingReply& p) {
                   // The time we sent is the loop clock in µs (ping()); the robot echoes it.
                   auto now = std::chrono::duration_cast<std::chrono::microseconds>(loop_.now());
                   state_.lastPing = static_cast<double>(now.count() - p.time) / 1e6;
                   ++state_.pings;
                 },
                 [](const auto&) {},
             },
             response);
  if (auto callback = onResponse) callback(response);
}

// Reads PATH_FINDING until it holds a path or the deadline passes (BLE, after TARGET_NAVI).
void Alphabot::readPath(TimePoint deadline) {
  pathTimer_ = 0;
  if (closed_ || !link_->connected()) return;
  if (loop_.now() >= deadline) {
    bleError_ = "PATH_FINDING on " + address() + " still pending after " +
                formatNumber(toSeconds(options_.pathTimeout)) + " s" + ": no path delivered";
    return log::warn(kLog, bleError_);
  }
  link_->send(gatt::readRequest(static_cast<std::uint8_t>(Characteristic::PathFinding)));
  pathTimer_ = loop_.after(options_.pathPoll, [this, deadline] { readPath(deadline); });
}

// ---- to the robot ----

Alphabot::Sent Alphabot::transmit(std::vector<std::uint8_t> frame) {
  if (closed_) return Unexpected{label() + " is closed"};
  if (!link_->send(frame)) {
    std::string why = link_->refusal();
    return Unexpected{label() + ": nothing sent: " + (why.empty() ? "not connected" : why)};
  }
  return true;
}

Alphabot::Sent Alphabot::send(const ab::Request& request) {
  if (closed_) return Unexpected{label() + " is closed"};
  if (options_.wire == AlphabotOptions::Wire::Wlan)
    return transmit(ab::wlan::encode(request, options_.codec));
  if (const auto* ping = std::get_if<ab::Ping>(&request)) {
    auto sent = transmit(gatt::readRequest(static_cast<std::uint8_t>(Characteristic::PingClient)));
    if (sent) pingTimes_.push_back(ping->time);
    return sent;
  }
  auto value = ab::ble::encode(request);
  if (!value) {
    bleError_ = value.error().message;
    return Unexpected{label() + ": nothing sent: " + bleError_};
  }
  auto sent = transmit(gatt::write(static_cast<std::uint8_t>(value->characteristic), value->bytes));
  if (sent && std::holds_alternative<ab::NavigateTo>(request)) {
    if (pathTimer_) loop_.cancel(pathTimer_);
    const auto deadline = loop_.now() + options_.pathTimeout;
    pathTimer_ = loop_.after(Duration(0), [this, deadline] { readPath(deadline); });
  }
  return sent;
}

Alphabot::Sent Alphabot::query(ab::ble::SensorKind kind) {
  if (options_.wire != AlphabotOptions::Wire::Ble)
    return Unexpected{label() + ": a sensor query is a BLE request; over WLAN nothing is sent"};
  auto value = ab::ble::encode(ab::ble::SensorQuery{kind});
  if (!value) return Unexpected{label() + ": nothing sent: " + value.error().message};
  return transmit(gatt::write(static_cast<std::uint8_t>(value->characteristic), value->bytes));
}

Alphabot::Sent Alphabot::drive(long long speed, long long steer) {
  if (auto e = outside("speed", speed, ab::kDriveMin, ab::kDriveMax)) return Unexpected{*e};
  if (auto e = outside("steer", steer, ab::kDriveMin, ab::kDriveMax)) return Unexpected{*e};
  return send(ab::Drive{static_cast<std::int8_t>(speed), static_cast<std::int8_t>(steer)});
}
Alphabot::Sent Alphabot::stop() {
  return send(ab::Drive{0, 0});
}
Alphabot::Sent Alphabot::measureDistance(long long degree) {
  if (auto e = outside("degree", degree, ab::kDegreeMin, ab::kDegreeMax)) return Unexpected{*e};
  return send(ab::MeasureDistance{i16(degree)});
}
Alphabot::Sent Alphabot::calibrateSteering() {
  return send(ab::CalibrateSteering{});
}
Alphabot::Sent Alphabot::calibrateCompass() {
  return send(ab::CalibrateCompass{});
}
Alphabot::Sent Alphabot::setToggles(const ab::Toggles& toggles) {
  auto sent = send(ab::SetToggles{toggles});
  if (sent) state_.toggles = toggles;
  return sent;
}
Alphabot::Sent Alphabot::ping() {
  auto now = std::chrono::duration_cast<std::chrono::microseconds>(loop_.now());
  return send(ab::Ping{static_cast<std::int64_t>(now.count())});
}
Alphabot::Sent Alphabot::setAnchor(long long id, long long x, long long y) {
  if (auto e = outside("anchor id", id, ab::kIdMin, ab::kIdMax)) return Unexpected{*e};
  if (auto e = outside("x (cm)", x, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  if (auto e = outside("y (cm)", y, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  return send(ab::SetAnchor{static_cast<std::uint8_t>(id), i16(x), i16(y)});
}
Alphabot::Sent Alphabot::navigateTo(long long x, long long y) {
  if (auto e = outside("x (cm)", x, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  if (auto e = outside("y (cm)", y, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  return send(ab::NavigateTo{i16(x), i16(y)});
}
Alphabot::Sent Alphabot::addObstacle(long long x, long long y, long long width, long long height) {
  if (auto e = outside("x (cm)", x, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  if (auto e = outside("y (cm)", y, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  if (auto e = outside("width (cm)", width, ab::kSizeMin, ab::kSizeMax)) return Unexpected{*e};
  if (auto e = outside("height (cm)", height, ab::kSizeMin, ab::kSizeMax)) return Unexpected{*e};
  return send(ab::AddObstacle{i16(x), i16(y), static_cast<std::uint16_t>(width),
                              static_cast<std::uint16_t>(height)});
}
Alphabot::Sent Alphabot::removeObstacle(long long id) {
  if (auto e = outside("obstacle id", id, ab::kIdMin, ab::kIdMax)) return Unexpected{*e};
  return send(ab::RemoveObstacleById{static_cast<std::uint8_t>(id)});
}
Alphabot::Sent Alphabot::removeObstacleAt(long long x, long long y) {
  if (auto e = outside("x (cm)", x, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  if (auto e = outside("y (cm)", y, ab::kCoordMin, ab::kCoordMax)) return Unexpected{*e};
  return send(ab::RemoveObstacleAt{i16(x), i16(y)});
}
Alphabot::Sent Alphabot::clearObstacles() {
  return send(ab::ClearObstacles{});
}

}  // namespace pitwall
