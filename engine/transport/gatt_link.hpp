#pragma once
// A link to a BLE peripheral whose profile is a set of characteristics (the Alphabot's eight),
// through BlueZ (docs/bluetooth.md). Its frames carry one characteristic each, named by its
// index in the profile:
//   to the device:   [index]             a read request (ReadValue)
//                    [index, value…]     a write (WriteValue, with response)
//   from the device: [index, value…]     a notification
//                    [index|0x80, value…] the answer to a read request
// so the model above decides what to read and when (polling, a read as a ping); the link only
// moves values.
//
//  - Find: the address in BlueZ's tree; when BlueZ does not know it, LE discovery (no service
//    filter: a profile may have no service UUID to look for) until it is seen or the scan time
//    is over ("no <profile> with the address … found"), then retried with backoff.
//  - Connect: GattClient's steps (Connect, ServicesResolved, each with its timeout), then the
//    profile's characteristics by UUID (a missing one fails the attempt, naming it), then
//    notifications on the notified ones (AcquireNotify sockets; StartNotify and
//    PropertiesChanged when BlueZ refuses), then up.
//  - Keep: a drop is reconnected with backoff (0.5 s doubling to 8 s); disconnect() hangs up
//    for good, as does destroying the link.
//
// Each link owns its system-bus connection, DbusPump and Bluez: Bluez has one subscriber per
// change callback, which the Anki Central already takes. Making the link makes three synchronous
// AddMatch calls to dbus-daemon (sdbus-c++ 1.2.0 has no asynchronous one): a millisecond or so.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/transport/gatt_client.hpp"
#include "engine/transport/link.hpp"

namespace pitwall {

// The frames of a GattLink.
namespace gatt {
inline constexpr std::uint8_t kReadAnswer = 0x80;
struct Value {
  std::uint8_t index = 0;
  bool readAnswer = false;
  std::span<const std::uint8_t> bytes;
};
// A frame from the device; nullopt when empty.
inline std::optional<Value> parse(std::span<const std::uint8_t> frame) {
  if (frame.empty()) return std::nullopt;
  return Value{static_cast<std::uint8_t>(frame[0] & ~kReadAnswer), (frame[0] & kReadAnswer) != 0,
               frame.subspan(1)};
}
inline std::vector<std::uint8_t> readRequest(std::uint8_t index) {
  return {index};
}
inline std::vector<std::uint8_t> write(std::uint8_t index, std::span<const std::uint8_t> value) {
  std::vector<std::uint8_t> frame{index};
  frame.insert(frame.end(), value.begin(), value.end());
  return frame;
}
}  // namespace gatt

struct GattProfile {
  std::string name;  // "Alphabot": in sentences
  struct Characteristic {
    std::string name;  // "DRIVE_STEER"
    std::string uuid;  // lower case
    bool notify = false;
  };
  std::vector<Characteristic> characteristics;  // by frame index
};

struct GattLinkOptions {
  std::string adapter;  // hci0 or its address; empty: the first adapter
  Duration scan = std::chrono::seconds(5);
  Duration backoffMin = std::chrono::milliseconds(500);
  Duration backoffMax = std::chrono::seconds(8);
  ble::LinkTimeouts timeouts;
};

class GattLink : public Link {
 public:
  // Throws ble::BleError when there is no system bus. Starts on the loop (after the caller has
  // set the handlers). `address` is AA:BB:CC:DD:EE:FF in upper case (makeGattLink checks it).
  GattLink(Loop& loop, std::string address, GattProfile profile, GattLinkOptions options);
  ~GattLink() override;

  bool send(std::span<const std::uint8_t> frame) override;
  bool connected() const override;
  void disconnect() override;
  // Hangs up (reporting `reason`) and connects again after the backoff.
  void reconnect(const std::string& reason) override;
  std::string address() const override { return "ble:" + address_; }
  // Down: why ("ble:…: not connected (…)"); up: the last failed write or read, or empty.
  std::string refusal() const override;
  // [index, value…]: written with WriteValue from the watchdog's thread while the link is up
  void setEmergencyStop(std::span<const std::uint8_t> frame) override;

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
  void notified(std::size_t index, std::span<const std::uint8_t> bytes);
  void write(std::size_t index, std::vector<std::uint8_t> value);
  void read(std::size_t index);
  void retryLater(const std::string& why);
  void reportDown(const std::string& why);
  void closeSockets();
  void stopScan();
  void registerEmergency(bool up);

  Loop& loop_;
  std::string address_;
  GattProfile profile_;
  GattLinkOptions options_;
  std::unique_ptr<ble::Bluez> bluez_;
  std::unique_ptr<ble::GattClient> gatt_;
  std::vector<std::string> paths_;  // characteristic object paths, by index
  std::vector<std::unique_ptr<ble::NotifySocket>> sockets_;  // by index; null: not notified
  std::string lastError_;
  int failures_ = 0, attempts_ = 0;
  bool closed_ = false, reportedDown_ = false;
  std::string scanning_;  // the adapter discovering for us
  Loop::TimerId retry_ = 0, scanTimer_ = 0;
  std::vector<std::uint8_t> emergencyStop_;
  int emergencyStopper_ = 0;
  std::shared_ptr<bool> alive_;
};

// Makes a link to the device at `address` (AA:BB:CC:DD:EE:FF, any case) with its own system-bus
// connection; it connects on the loop, reporting through onState. nullptr and `error` set when
// the address is malformed or there is no system bus.
std::unique_ptr<GattLink> makeGattLink(Loop& loop, const std::string& address, GattProfile profile,
                                       GattLinkOptions options, std::string& error);

}  // namespace pitwall
