#pragma once
// One BLE peripheral through BlueZ, whatever its GATT profile (docs/bluetooth.md): the steps every
// connection takes, each with its own timeout and an error that names it —
//   connect (Device1.Connect) → service discovery (ServicesResolved) → the profile's setup
//   (characteristics by UUID, notifications, writes) → up
// — then a loss once up (Connected going false, the device vanishing, a notification socket
// closing) and Disconnect. The profile is the owner: BleLink (an Anki car: two characteristics)
// or the Alphabot's link (eight). It sets the hooks before connect(); in onResolved it finds its
// characteristics and subscribes, then calls ready() or fail().
//
// Replies of an attempt that has ended are ignored: every asynchronous step checks current().
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "engine/transport/bluez.hpp"

namespace pitwall::ble {

struct LinkTimeouts {
  Duration connect = std::chrono::seconds(10);
  Duration resolve = std::chrono::seconds(10);
  Duration subscribe = std::chrono::seconds(5);
  Duration disconnect = std::chrono::seconds(2);
};

class GattClient {
 public:
  using Done = std::function<void(std::optional<std::string> error)>;

  GattClient(Bluez& bluez, std::string devicePath, std::string address, LinkTimeouts timeouts);
  ~GattClient();
  GattClient(const GattClient&) = delete;
  GattClient& operator=(const GattClient&) = delete;

  // Runs the connection sequence; done(error) once up (after ready()) or once the attempt failed.
  void connect(Done done);
  // The profile's setup is complete: the link is up.
  void ready();
  // The attempt failed before the link came up (a missing characteristic, a refused subscribe).
  void fail(const std::string& reason);
  // The link was up and went down (e.g. a notification socket closed).
  void lost(const std::string& reason);
  // The profile gives the link up (it takes no writes): Device1.Disconnect, and lost(reason).
  void drop(const std::string& reason) {
    disconnectQuietly();
    lost(reason);
  }
  // Asks BlueZ to disconnect; done() when it has (or after the disconnect timeout).
  void disconnect(std::function<void()> done);

  // BlueZ's tree, from whoever follows it (the Central, or the profile's own Bluez).
  void deviceChanged(const Device& device);
  void deviceRemoved();
  void retarget(std::string devicePath) { devicePath_ = std::move(devicePath); }

  bool up() const { return step_ == Step::Up; }
  bool idle() const { return step_ == Step::Idle; }
  const std::string& devicePath() const { return devicePath_; }
  const std::string& address() const { return address_; }  // AA:BB:…
  std::string label() const { return "ble:" + address_; }  // for the log
  Bluez& bluez() { return bluez_; }
  const Bluez& bluez() const { return bluez_; }
  const LinkTimeouts& timeouts() const { return timeouts_; }

  // For the profile's own asynchronous steps: the attempt a reply belongs to.
  std::uint64_t attempt() const { return attempt_; }
  bool current(std::uint64_t attempt) const { return attempt == attempt_; }
  // A timeout for the profile's setup step: fail("<what> timed out after …") — except while a
  // setup call (below) waits for bluetoothd's answer: then the step waits for that answer (as long
  // as kSetupCallLimit), and the timeout starts again after it. A Disconnect while bluetoothd
  // still writes a car's notification setting leaves BlueZ before 5.84 holding the notifications
  // ("Notify acquired", refused until bluetoothd restarts: docs/bluetooth.md), so a slow car is
  // waited for rather than dropped.
  void armStepTimer(Duration timeout, std::string what);
  // How long a setup call may wait for bluetoothd: past BlueZ's ATT transaction timeout (30 s),
  // after which bluetoothd itself has given up on the car and answered.
  static constexpr Duration kSetupCallLimit = std::chrono::seconds(35);
  // AcquireNotify/AcquireWrite on `path`; then(error or nullptr, the socket) for this attempt.
  void acquire(const std::string& path, const char* method,
               std::function<void(const sdbus::Error*, int fd)> then);
  // StartNotify on `path`; then(error or nullptr) for this attempt.
  void startNotify(const std::string& path, std::function<void(const sdbus::Error*)> then);

  // The attempt or the link ended: close the profile's sockets.
  std::function<void()> onClosed;
  // Up, or down after being up (with the reason; "disconnected by the controller" when asked).
  std::function<void(bool up, const std::string& reason)> onState;
  // A loss the controller did not ask for: reconnect.
  std::function<void(const std::string& reason)> onDropped;
  // Services resolved: the profile's setup starts here.
  std::function<void()> onResolved;

 private:
  enum class Step { Idle, Connecting, Resolving, Setup, Up };
  void resolved();
  void disconnectQuietly();  // Device1.Disconnect, nobody waiting for the answer
  void setupCallSent() { ++setupCalls_; }
  void setupCallAnswered();

  Bluez& bluez_;
  // The loop itself, not through bluez_: a link may outlive the Bluez (the fleet that holds the
  // links is destroyed after the Central that owns the Bluez), and its destructor still cancels
  // the step timer (found by the ASan unit run, docs/testing.md).
  Loop& loop_;
  std::string devicePath_, address_;
  LinkTimeouts timeouts_;
  Step step_ = Step::Idle;
  std::uint64_t attempt_ = 0;
  Done done_;
  Loop::TimerId stepTimer_ = 0;
  Duration stepTimeout_{};
  std::string stepWhat_;
  int setupCalls_ = 0;        // setup calls bluetoothd has not answered yet (any attempt's)
  bool stepOverdue_ = false;  // the step's timeout passed while one was waiting
  bool disconnectRequested_ = false;
  bool sawConnected_ = false;  // BlueZ's Connected as last seen
  std::shared_ptr<bool> alive_;
};

// An AcquireNotify socket: one datagram per notification, read on the loop.
class NotifySocket {
 public:
  // onValue(bytes) per notification; onClosed(error) once when BlueZ closed it (error empty) or
  // it failed. Neither is called after close() or destruction.
  using ValueHandler = std::function<void(std::span<const std::uint8_t>)>;
  using ClosedHandler = std::function<void(const std::string& error)>;

  explicit NotifySocket(boost::asio::io_context& io) : fd_(io) {}
  ~NotifySocket() { close(); }
  void open(int fd, ValueHandler onValue, ClosedHandler onClosed);
  void close();
  bool isOpen() const { return fd_.is_open(); }

 private:
  void wait();
  boost::asio::posix::stream_descriptor fd_;
  ValueHandler onValue_;
  ClosedHandler onClosed_;
  std::shared_ptr<int> token_;  // replaced on open, reset on close: handlers of old sockets stop
};

}  // namespace pitwall::ble
