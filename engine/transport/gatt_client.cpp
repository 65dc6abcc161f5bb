#include "engine/transport/gatt_client.hpp"

#include <sys/socket.h>

#include <sdbus-c++/sdbus-c++.h>
#include <algorithm>
#include <cerrno>
#include <cstring>

#include "engine/core/log.hpp"

namespace pitwall::ble {

namespace {
std::string seconds(Duration d) {
  auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
  return ms % 1000 == 0 ? std::to_string(ms / 1000) + " s" : std::to_string(ms) + " ms";
}
}  // namespace

GattClient::GattClient(Bluez& bluez, std::string devicePath, std::string address,
                       LinkTimeouts timeouts)
    : bluez_(bluez),
      loop_(bluez.loop()),
      devicePath_(std::move(devicePath)),
      address_(std::move(address)),
      timeouts_(timeouts),
      alive_(std::make_shared<bool>(true)) {}

GattClient::~GattClient() {
  *alive_ = false;
  loop_.cancel(stepTimer_);
}

void GattClient::armStepTimer(Duration timeout, std::string what) {
  bluez_.loop().cancel(stepTimer_);
  stepTimeout_ = timeout;
  stepWhat_ = std::move(what);
  stepOverdue_ = false;
  auto attempt = attempt_;
  stepTimer_ = bluez_.loop().after(timeout, [this, attempt] {
    stepTimer_ = 0;
    if (!current(attempt)) return;
    if (setupCalls_ > 0) {
      stepOverdue_ = true;
      log::info(label(), stepWhat_ + " takes longer than " + seconds(stepTimeout_) +
                             ": waiting for BlueZ's answer (giving up now would leave bluetoothd "
                             "before 5.84 holding the car's notifications)");
      return;
    }
    fail(stepWhat_ + " timed out after " + seconds(stepTimeout_));
  });
}

void GattClient::setupCallAnswered() {
  --setupCalls_;
  // (stepOverdue_ is the current attempt's: armStepTimer and fail() reset it)
  if (setupCalls_ == 0 && stepOverdue_) {
    // the step goes on from here with its timeout anew (ready() or fail() cancel it)
    armStepTimer(stepTimeout_, stepWhat_);
  }
}

void GattClient::connect(Done done) {
  if (step_ != Step::Idle) {
    if (done)
      done(step_ == Step::Up ? std::nullopt : std::optional<std::string>("already connecting"));
    return;
  }
  auto attempt = ++attempt_;
  done_ = std::move(done);
  disconnectRequested_ = false;
  stepOverdue_ = false;
  step_ = Step::Connecting;
  std::weak_ptr<bool> alive = alive_;
  log::debug(label(), "connecting");
  bluez_.proxy(devicePath_)
      .callMethodAsync("Connect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.connect)
      .uponReplyInvoke([this, alive, attempt](const sdbus::Error* error) {
        if (alive.expired()) return;
        if (!current(attempt)) {
          if (!error && step_ == Step::Idle) disconnectQuietly();  // given up, yet connected
          return;
        }
        if (error && error->getName() != "org.bluez.Error.AlreadyConnected")
          return fail(describe(*error, "connecting to " + address_));
        step_ = Step::Resolving;
        const Device* d = bluez_.device(devicePath_);
        sawConnected_ = d && d->connected;
        if (d && d->servicesResolved) return resolved();
        armStepTimer(timeouts_.resolve, "service discovery on " + address_);
      });
  bluez_.pump().kick();
}

void GattClient::deviceChanged(const Device& d) {
  // A loss is Connected going from true to false. BlueZ may answer Connect before its
  // Connected=true signal arrives: a false seen before any true is not a loss.
  bool wasConnected = sawConnected_;
  sawConnected_ = d.connected;
  // (A Connect given up on is cancelled when it is given up: fail().)
  if (step_ == Step::Idle) return;
  if (!d.connected && wasConnected && step_ != Step::Connecting) {
    if (step_ == Step::Up)
      lost(address_ + " disconnected");
    else
      fail(address_ + " disconnected during " +
           (step_ == Step::Resolving ? "service discovery" : "setup"));
    return;
  }
  if (step_ == Step::Resolving && d.servicesResolved) resolved();
}

void GattClient::deviceRemoved() {
  if (step_ == Step::Up)
    lost(address_ + " vanished from BlueZ");
  else if (step_ != Step::Idle)
    fail(address_ + " vanished from BlueZ");
}

void GattClient::resolved() {
  bluez_.loop().cancel(stepTimer_);
  step_ = Step::Setup;
  if (onResolved)
    onResolved();
  else
    ready();
}

void GattClient::acquire(const std::string& path, const char* method,
                         std::function<void(const sdbus::Error*, int fd)> then) {
  auto attempt = attempt_;
  std::weak_ptr<bool> alive = alive_;
  bluez_.proxy(path)
      .callMethodAsync(method)
      .onInterface(kCharIface)
      .withTimeout(std::max(timeouts_.subscribe, kSetupCallLimit))
      .withArguments(std::map<std::string, sdbus::Variant>{})
      .uponReplyInvoke([this, alive, attempt, method, then](
                           const sdbus::Error* error, sdbus::UnixFd fd, std::uint16_t /*mtu*/) {
        if (alive.expired()) return;
        setupCallAnswered();
        if (!current(attempt)) return;
        if (error) log::debug(label(), std::string(method) + " refused (" + error->getName() + ")");
        then(error, error ? -1 : fd.release());
      });
  setupCallSent();  // (once sent: its answer comes through the loop, after this)
  bluez_.pump().kick();
}

void GattClient::startNotify(const std::string& path,
                             std::function<void(const sdbus::Error*)> then) {
  auto attempt = attempt_;
  std::weak_ptr<bool> alive = alive_;
  bluez_.proxy(path)
      .callMethodAsync("StartNotify")
      .onInterface(kCharIface)
      .withTimeout(std::max(timeouts_.subscribe, kSetupCallLimit))
      .uponReplyInvoke([this, alive, attempt, then](const sdbus::Error* error) {
        if (alive.expired()) return;
        setupCallAnswered();
        if (!current(attempt)) return;
        then(error);
      });
  setupCallSent();
  bluez_.pump().kick();
}

void GattClient::ready() {
  bluez_.loop().cancel(stepTimer_);
  stepOverdue_ = false;
  step_ = Step::Up;
  auto done = std::move(done_);
  done_ = nullptr;
  if (onState) onState(true, "connected");
  if (done) done(std::nullopt);
}

void GattClient::fail(const std::string& reason) {
  bool reachedDevice = step_ != Step::Connecting;
  ++attempt_;  // replies still on their way belong to a finished attempt
  bluez_.loop().cancel(stepTimer_);
  stepOverdue_ = false;
  if (onClosed) onClosed();
  step_ = Step::Idle;
  // Half-connected: leave BlueZ clean for the next attempt.
  if (reachedDevice) {
    const Device* d = bluez_.device(devicePath_);
    if (d && d->connected) disconnectQuietly();
  } else {
    // A Connect given up on (timed out, or refused as one already under way) may still pend
    // in bluetoothd, which answers every next one InProgress for as long as it keeps trying:
    // Disconnect cancels it (org.bluez.Device1), so the next attempt is a fresh one. Seen
    // against the real bluetoothd after its restart (tests/qemu, 2026-11-29). (Should BlueZ
    // have connected meanwhile, the same Disconnect hangs up, or the device would stay taken
    // and invisible to the next scan.)
    disconnectQuietly();
  }
  auto done = std::move(done_);
  done_ = nullptr;
  if (done) done(reason);
}

void GattClient::disconnectQuietly() {
  bluez_.proxy(devicePath_)
      .callMethodAsync("Disconnect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.disconnect)
      .uponReplyInvoke([](const sdbus::Error*) {});
  bluez_.pump().kick();
}

void GattClient::lost(const std::string& reason) {
  ++attempt_;
  if (onClosed) onClosed();
  step_ = Step::Idle;
  bool requested = disconnectRequested_;
  if (onState) onState(false, requested ? "disconnected by the controller" : reason);
  if (!requested && onDropped) onDropped(reason);
}

void GattClient::disconnect(std::function<void()> done) {
  disconnectRequested_ = true;
  if (step_ == Step::Idle) {
    if (done) done();
    return;
  }
  std::weak_ptr<bool> alive = alive_;
  auto finished = std::make_shared<bool>(false);
  auto finish = [this, alive, finished, done] {
    if (*finished) return;
    *finished = true;
    if (!alive.expired() && step_ == Step::Up) lost("disconnected by the controller");
    if (!alive.expired() && step_ != Step::Idle) fail("disconnected by the controller");
    if (done) done();
  };
  bluez_.proxy(devicePath_)
      .callMethodAsync("Disconnect")
      .onInterface(kDeviceIface)
      .withTimeout(timeouts_.disconnect)
      .uponReplyInvoke([finish](const sdbus::Error*) { finish(); });
  bluez_.pump().kick();
}

// ---- NotifySocket ----

void NotifySocket::open(int fd, ValueHandler onValue, ClosedHandler onClosed) {
  close();
  fd_.assign(fd);
  onValue_ = std::move(onValue);
  onClosed_ = std::move(onClosed);
  token_ = std::make_shared<int>(0);
  wait();
}

void NotifySocket::close() {
  token_.reset();
  boost::system::error_code ec;
  if (fd_.is_open()) fd_.close(ec);
}

void NotifySocket::wait() {
  std::weak_ptr<int> token = token_;
  fd_.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                 [this, token](const boost::system::error_code& ec) {
                   if (token.expired() || ec == boost::asio::error::operation_aborted) return;
                   auto closed = [this](const std::string& why) {
                     auto handler = onClosed_;
                     close();
                     if (handler) handler(why);
                   };
                   if (ec) return closed(ec.message());
                   std::uint8_t buf[512];  // one datagram is one notification
                   for (;;) {
                     ssize_t n = ::recv(fd_.native_handle(), buf, sizeof buf, MSG_DONTWAIT);
                     if (n > 0) {
                       onValue_(std::span<const std::uint8_t>(buf, std::size_t(n)));
                       if (token.expired()) return;  // the handler closed or destroyed us
                       continue;
                     }
                     if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
                     if (n < 0 && errno == EINTR) continue;
                     return closed(n == 0 ? std::string() : std::string(std::strerror(errno)));
                   }
                   wait();
                 });
}

}  // namespace pitwall::ble
