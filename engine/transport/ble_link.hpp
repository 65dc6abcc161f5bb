#pragma once
// A Link to one Anki car through BlueZ (docs/bluetooth.md). The connection sequence, each step
// with its own timeout and an error that names it:
//   connect (Device1.Connect) → service discovery (ServicesResolved) → characteristics by UUID →
//   notifications (AcquireNotify: a socket, lowest latency; StartNotify when BlueZ or the car
//   refuses) → writes (AcquireWrite; WriteValue without response as the fallback) → up.
// Frames then flow both ways on the engine loop. Reconnection is the Central's job: the link
// reports a loss it did not ask for through onDropped.
#include <boost/asio/posix/stream_descriptor.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/transport/bluez.hpp"
#include "engine/transport/link.hpp"

namespace pitwall::ble {

struct LinkTimeouts {
  Duration connect = std::chrono::seconds(10);
  Duration resolve = std::chrono::seconds(10);
  Duration subscribe = std::chrono::seconds(5);
  Duration disconnect = std::chrono::seconds(2);
};

class BleLink : public Link {
 public:
  using Done = std::function<void(std::optional<std::string> error)>;

  BleLink(Bluez& bluez, std::string devicePath, std::string address, LinkTimeouts timeouts = {});
  ~BleLink() override;

  // Runs the connection sequence; done(error) once the link is up or the attempt failed. The
  // state handler (Link::onState) reports up, and later down.
  void connect(Done done);

  bool send(std::span<const std::uint8_t> frame) override;
  bool connected() const override { return step_ == Step::Up; }
  void disconnect() override { disconnect(nullptr); }
  // Asks BlueZ to disconnect; done() when it has (or after the disconnect timeout).
  void disconnect(std::function<void()> done);
  std::string address() const override { return "ble:" + address_; }

  // From the Central, which follows BlueZ's tree for all links.
  const std::string& devicePath() const { return devicePath_; }
  const std::string& notifyPath() const { return readChar_; }
  void retarget(std::string devicePath) { devicePath_ = std::move(devicePath); }
  void deviceChanged(const Device& device);
  void deviceRemoved();
  void value(const std::vector<std::uint8_t>& frame);  // a notification through PropertiesChanged

  // How frames travel (for tests, benchmarks and `--log-level debug`).
  bool notifyAcquired() const { return notifyFd_.is_open(); }
  bool writeAcquired() const { return writeFd_.is_open(); }

  // A loss the controller did not ask for: the Central reconnects.
  std::function<void(const std::string& reason)> onDropped;

 private:
  enum class Step { Idle, Connecting, Resolving, Subscribing, Up };
  void resolved();
  void subscribe();
  void acquireWrite();
  // AcquireNotify/AcquireWrite on `path`; then(error or nullptr, the socket) for this attempt.
  void acquire(const std::string& path, const char* method,
               std::function<void(const sdbus::Error*, int fd)> then);
  void up();
  void fail(const std::string& reason);  // an attempt failed before the link came up
  void lost(const std::string& reason);  // the link was up and went down
  void closeChannels();
  void disconnectQuietly();  // Device1.Disconnect, nobody waiting for the answer
  void waitNotify();
  void writeValue(std::span<const std::uint8_t> frame);
  bool current(std::uint64_t attempt) const { return attempt == attempt_; }
  void armStepTimer(Duration timeout, std::string what);

  Bluez& bluez_;
  std::string devicePath_, address_;
  LinkTimeouts timeouts_;
  Step step_ = Step::Idle;
  std::uint64_t attempt_ = 0;
  Done done_;
  Loop::TimerId stepTimer_ = 0;
  std::string readChar_, writeChar_;
  bool disconnectRequested_ = false;
  bool sawConnected_ = false;      // BlueZ's Connected as last seen
  bool abandonedConnect_ = false;  // the last attempt gave up while Connect was under way
  boost::asio::posix::stream_descriptor notifyFd_, writeFd_;
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall::ble
