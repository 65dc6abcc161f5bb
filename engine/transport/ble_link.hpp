#pragma once
// A Link to one Anki car through BlueZ (docs/bluetooth.md). The connection sequence, each step
// with its own timeout and an error that names it:
//   connect (Device1.Connect) → service discovery (ServicesResolved) → characteristics by UUID →
//   notifications (AcquireNotify: a socket, lowest latency; StartNotify when BlueZ or the car
//   refuses) → writes (AcquireWrite; WriteValue without response as the fallback) → up.
// The steps up to service discovery, the loss and Disconnect are GattClient's (gatt_client.hpp);
// the Anki profile (two characteristics) is here. Frames then flow both ways on the engine loop.
// Reconnection is the Central's job: the link reports a loss it did not ask for through onDropped.
#include <boost/asio/posix/stream_descriptor.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/transport/bluez.hpp"
#include "engine/transport/gatt_client.hpp"
#include "engine/transport/link.hpp"

namespace pitwall::ble {

class BleLink : public Link {
 public:
  using Done = std::function<void(std::optional<std::string> error)>;

  BleLink(Bluez& bluez, std::string devicePath, std::string address, LinkTimeouts timeouts = {});
  ~BleLink() override;

  // Runs the connection sequence; done(error) once the link is up or the attempt failed. The
  // state handler (Link::onState) reports up, and later down.
  void connect(Done done);

  bool send(std::span<const std::uint8_t> frame) override;
  // Drops the link (Device1.Disconnect) with `reason`; the Central connects it again.
  void reconnect(const std::string& reason) override;
  std::string refusal() const override;
  bool connected() const override { return gatt_.up(); }
  void disconnect() override { disconnect(nullptr); }
  // Asks BlueZ to disconnect; done() when it has (or after the disconnect timeout).
  void disconnect(std::function<void()> done) { gatt_.disconnect(std::move(done)); }
  std::string address() const override { return gatt_.label(); }
  void setEmergencyStop(std::span<const std::uint8_t> frame) override;

  // From the Central, which follows BlueZ's tree for all links.
  const std::string& devicePath() const { return gatt_.devicePath(); }
  const std::string& notifyPath() const { return readChar_; }
  void retarget(std::string devicePath) { gatt_.retarget(std::move(devicePath)); }
  void deviceChanged(const Device& device) { gatt_.deviceChanged(device); }
  void deviceRemoved() { gatt_.deviceRemoved(); }
  void value(const std::vector<std::uint8_t>& frame);  // a notification through PropertiesChanged

  // How frames travel (for tests, benchmarks and `--log-level debug`).
  bool notifyAcquired() const { return notify_.isOpen(); }
  bool writeAcquired() const { return writeFd_.is_open(); }

  // A loss the controller did not ask for: the Central reconnects.
  std::function<void(const std::string& reason)> onDropped;

  // A write socket that takes nothing for this long has its link dropped (send()).
  static constexpr double kWriteStall = 1.0;
  // What went wrong on this link so far, and the car's RSSI as BlueZ last reported it.
  LinkHealth health() const override;

 private:
  void resolved();
  void subscribe();
  void acquireWrite();
  void up();
  void closeChannels();
  void writeValue(std::span<const std::uint8_t> frame);
  void closeWrite();  // the write socket, after its emergency slot is given back
  // The stop outside the loop: the write socket's slot, or a stopper writing with WriteValue
  void registerEmergency();

  GattClient gatt_;
  std::string readChar_, writeChar_;
  NotifySocket notify_;
  boost::asio::posix::stream_descriptor writeFd_;
  std::vector<std::uint8_t> emergencyStop_;
  int emergencySlot_ = -1;
  int emergencyStopper_ = 0;
  std::optional<double> stalledSince_;  // since when the write socket is full
  int failing_ = 0;                     // WriteValue errors since the last write that went through
  LinkHealth health_;                   // writeFailures, stalls
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall::ble
