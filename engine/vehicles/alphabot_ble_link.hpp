#pragma once
// An Alphabot over Bluetooth LE: its GATT service through BlueZ, one characteristic per function
// (docs/robots.md, engine/protocol/alphabot/ble_codec.hpp).
//
//  - Find: the address in BlueZ's tree; when BlueZ does not know it, LE discovery (no service
//    filter: the reference gives the Alphabot no service UUID) until it is seen or the scan time
//    is over ("no Alphabot … found"), then retried with backoff.
//  - Connect: GattClient's steps (Connect, ServicesResolved, each with its timeout), then the
//    eight characteristics by UUID (a missing one fails the attempt, naming it), then
//    notifications on SENSOR, TOGGLE, OBSTACLE, PINGCLIENT and CALIBRATE (AcquireNotify sockets;
//    StartNotify and PropertiesChanged when BlueZ refuses), then up.
//  - Requests: WriteValue (with response: the characteristics are "write", not
//    "write-without-response") on the request's characteristic. After TARGET_NAVI is written,
//    PATH_FINDING is read (again every pathPoll while the robot says "pending", up to
//    pathTimeout) and delivered as a Path. A Ping is a read of PINGCLIENT: the reply is the
//    robot's answer, delivered as PingReply with the request's time.
//  - Keep: a drop is reconnected with backoff (0.5 s doubling to 8 s); close() disconnects.
//
// Each link owns its system-bus connection, DbusPump and Bluez: Bluez has one subscriber per
// change callback, which the Anki Central already takes. Making the link makes three synchronous
// AddMatch calls to dbus-daemon (sdbus-c++ 1.2.0 has no asynchronous one): a millisecond or so.
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "engine/protocol/alphabot/ble_codec.hpp"
#include "engine/transport/gatt_client.hpp"
#include "engine/vehicles/alphabot_link.hpp"

namespace pitwall::alphabot {

struct BleLinkOptions {
  std::string adapter;  // hci0 or its address; empty: the first adapter
  Duration scan = std::chrono::seconds(5);
  Duration backoffMin = std::chrono::milliseconds(500);
  Duration backoffMax = std::chrono::seconds(8);
  Duration pathPoll = std::chrono::milliseconds(100);
  Duration pathTimeout = std::chrono::seconds(2);
  ::pitwall::ble::LinkTimeouts timeouts;
};

class AlphabotBleLink : public RobotLink {
 public:
  // Throws ::pitwall::ble::BleError when there is no system bus. Starts on the loop (after the
  // caller has set the handlers).
  AlphabotBleLink(Loop& loop, std::string address, BleLinkOptions options);
  ~AlphabotBleLink() override;

  bool send(const Request& request) override;
  // BLE only: a SENSOR request for the compass, the map size or the position.
  bool query(ble::SensorKind kind);
  bool connected() const override;
  void close() override;
  std::string address() const override { return "ble:" + address_; }
  std::string lastError() const override { return lastError_; }

  // The robot's toggles as it last notified them; heartbeats (PINGCLIENT notifications) seen.
  std::optional<Toggles> toggles() const { return toggles_; }
  int heartbeats() const { return heartbeats_; }
  int attempts() const { return attempts_; }
  // Notifications by socket (AcquireNotify) rather than by PropertiesChanged, for tests.
  bool notifyAcquired() const;

 private:
  void start();
  void findDevice();
  void scanTimedOut();
  void connect(const std::string& devicePath);
  void resolved();
  void subscribe(std::size_t next);
  void notified(ble::Characteristic c, std::span<const std::uint8_t> bytes);
  void write(const ble::BleValue& value, bool thenReadPath);
  void read(ble::Characteristic c, std::function<void(std::vector<std::uint8_t>)> then);
  void readPath(TimePoint deadline);
  void retryLater(const std::string& why);
  void reportDown(const std::string& why);
  void closeSockets();
  void stopScan();
  const std::string& pathOf(ble::Characteristic c) const {
    return paths_[static_cast<std::size_t>(c)];
  }

  Loop& loop_;
  std::string address_;
  BleLinkOptions options_;
  std::unique_ptr<::pitwall::ble::Bluez> bluez_;
  std::unique_ptr<::pitwall::ble::GattClient> gatt_;
  std::array<std::string, 8> paths_;  // characteristic object paths, by ble::Characteristic
  std::array<std::unique_ptr<::pitwall::ble::NotifySocket>, 8> sockets_;
  std::string lastError_;
  std::optional<Toggles> toggles_;
  int heartbeats_ = 0, failures_ = 0, attempts_ = 0;
  bool closed_ = false, reportedDown_ = false, reportedUp_ = false;
  std::string scanning_;  // the adapter discovering for us
  Loop::TimerId retry_ = 0, scanTimer_ = 0;
  std::shared_ptr<bool> alive_;
};

// Makes a link to the Alphabot at `address` (AA:BB:CC:DD:EE:FF) with its own system-bus
// connection; it connects on the loop, reporting through onState. nullptr and `error` set when
// the address is malformed or there is no system bus.
std::unique_ptr<RobotLink> makeBleRobotLink(Loop& loop, const std::string& address,
                                            std::string& error);
std::unique_ptr<RobotLink> makeBleRobotLink(Loop& loop, const std::string& address,
                                            BleLinkOptions options, std::string& error);

}  // namespace pitwall::alphabot
