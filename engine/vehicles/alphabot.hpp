#pragma once
// The controller-side model of an Alphabot robot (../shared/protocols/alphabot.md; docs/robots.md)
// over a link, whichever way it is reached: WLAN (the packet protocol on a TCP link, framed by
// wlan::frameLength) or Bluetooth LE (the GATT characteristics on a GattLink, frames of one
// characteristic each: engine/transport/gatt_link.hpp). It owns what the robot last said
// (position, heading, path, pings), the toggles it was last sent, the count of malformed
// frames, validated commands, and the stop on close. Over BLE it also does what the
// characteristics need: after TARGET_NAVI it reads PATH_FINDING (again every pathPoll while
// the robot says "pending", up to pathTimeout) and a ping is a read of PINGCLIENT, whose answer
// is the reply.
//
// The link reconnects by itself; onConnection reports each connection and each outage.
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/core/warning_limit.hpp"
#include "engine/protocol/alphabot/ble_codec.hpp"
#include "engine/protocol/alphabot/messages.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "engine/transport/gatt_link.hpp"
#include "engine/transport/link.hpp"

namespace pitwall {

struct AlphabotState {
  alphabot::Toggles toggles;  // as last sent: set() changes only the bits it names
  std::optional<int> x, y, heading;
  std::optional<double> lastPing;  // s, round trip of the last ping reply
  std::size_t pings = 0;           // ping replies received
  std::vector<alphabot::Waypoint> path;
  std::size_t malformed = 0;  // frames that did not decode
  bool everConnected = false;
  int heartbeats = 0;                             // BLE: PINGCLIENT notifications seen
  std::optional<alphabot::Toggles> robotToggles;  // BLE: the toggles the robot last notified
};

struct AlphabotOptions {
  enum class Wire { Wlan, Ble };
  Wire wire = Wire::Wlan;
  alphabot::wlan::Options codec;                       // WLAN byte order
  Duration pathPoll = std::chrono::milliseconds(100);  // BLE: PATH_FINDING read again…
  Duration pathTimeout = std::chrono::seconds(2);      // …while pending, up to this
};

// The TCP link to an Alphabot at host:port, framed by its response packets; it starts
// connecting at once, each attempt bounded by connectTimeout (s).
std::unique_ptr<Link> makeAlphabotTcpLink(Loop& loop, const std::string& host, std::uint16_t port,
                                          double connectTimeout);

// The GATT link to an Alphabot at `address` (AA:BB:CC:DD:EE:FF): its eight characteristics by
// ble::Characteristic, the five it notifies subscribed. nullptr and `error` set when the address
// is malformed or there is no system bus.
std::unique_ptr<Link> makeAlphabotBleLink(Loop& loop, const std::string& address,
                                          GattLinkOptions options, std::string& error);

class Alphabot {
 public:
  using Sent = Result<bool, std::string>;  // true, or a sentence saying why nothing was sent

  Alphabot(Loop& loop, std::unique_ptr<Link> link, AlphabotOptions options = {});
  ~Alphabot();
  Alphabot(const Alphabot&) = delete;
  Alphabot& operator=(const Alphabot&) = delete;

  // Commands: validated (an error names the value and its range), then sent; refused with a
  // sentence when the robot is closed or not connected.
  Sent drive(long long speed, long long steer);
  Sent stop();
  Sent measureDistance(long long degree);
  Sent calibrateSteering();
  Sent calibrateCompass();
  Sent setToggles(const alphabot::Toggles& toggles);  // the whole field; kept as state
  Sent ping();                                        // the loop clock in µs travels with it
  Sent setAnchor(long long id, long long x, long long y);
  Sent navigateTo(long long x, long long y);
  Sent addObstacle(long long x, long long y, long long width, long long height);
  Sent removeObstacle(long long id);
  Sent removeObstacleAt(long long x, long long y);
  Sent clearObstacles();
  Sent query(alphabot::ble::SensorKind kind);  // BLE only: a SENSOR request
  Sent send(const alphabot::Request& request);

  // Ends the robot's part: a stop when connected, the link closed, no more events. Final.
  void close();
  bool closed() const { return closed_; }

  bool connected() const { return !closed_ && link_->connected(); }
  const AlphabotState& state() const { return state_; }
  std::string address() const { return link_->address(); }
  std::string label() const { return "alphabot " + link_->address(); }
  // Why the robot cannot take a command now, or what last went wrong over BLE; empty when fine.
  std::string lastError() const;
  Link& link() { return *link_; }

  // Events, on the loop; state() is already updated.
  std::function<void(const alphabot::Response&)> onResponse;
  // Up, or down with the reason: once per outage, the first failed attempt included (a model
  // that was never up has state().everConnected false).
  std::function<void(bool up, const std::string& reason)> onConnection;
  std::function<void(const std::string& error)> onMalformed;

 private:
  void linkChanged(bool up, const std::string& reason);
  void received(std::span<const std::uint8_t> frame);
  void receivedBle(std::span<const std::uint8_t> frame);
  void respond(const alphabot::Response& response);
  void malformed(const std::string& error);
  void readPath(TimePoint deadline);
  Sent transmit(std::vector<std::uint8_t> frame);

  Loop& loop_;
  std::unique_ptr<Link> link_;
  AlphabotOptions options_;
  AlphabotState state_;
  bool closed_ = false;
  std::string bleError_;                // BLE: an encoding refusal or a path that never came
  std::deque<std::int64_t> pingTimes_;  // BLE: pings whose PINGCLIENT read is under way
  Loop::TimerId pathTimer_ = 0;
  // A robot or link that sends only malformed packets: the first warned, then a count each 5 s.
  WarningLimit malformedWarnings_{loop_, "malformed packets"};
};

}  // namespace pitwall
