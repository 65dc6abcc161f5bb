#pragma once
// A link moves frames between the controller side (a vehicle model) and one device. Links are
// driven by the engine's one loop; callbacks run on it.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

namespace pitwall {

// What a link knows of its own health beyond up and down (car.link, docs/lua-api.md); a link
// that knows nothing of it leaves the defaults.
struct LinkHealth {
  int writeFailures = 0;    // writes the transport refused
  int stalls = 0;           // times the link was dropped because it took no write
  std::optional<int> rssi;  // dBm, where the transport tells it (BlueZ: while discovering)
};

class Link {
 public:
  using FrameHandler = std::function<void(std::span<const std::uint8_t>)>;
  using StateHandler = std::function<void(bool connected, const std::string& reason)>;

  virtual ~Link() = default;
  // Queues one frame to the device. Returns false (and sends nothing) when not connected.
  virtual bool send(std::span<const std::uint8_t> frame) = 0;
  virtual bool connected() const = 0;
  // Asks the device side to drop the connection; the state handler reports it.
  virtual void disconnect() = 0;
  // Drops the connection because the model above saw it fail (a device that stopped answering),
  // reporting `reason` through the state handler, and connects again the way the link does
  // after any drop. A link that does not reconnect by itself only disconnects.
  virtual void reconnect(const std::string& reason) {
    (void)reason;
    disconnect();
  }
  // A short human name of where the device is ("sim:0", "ble:AA:BB:…").
  virtual std::string address() const = 0;
  // After a drop, how long until the link tries again by itself; nullopt when it does not.
  virtual std::optional<double> retryIn() const { return std::nullopt; }
  // Why the last send() returned false, when the link knows more than "not connected": one
  // sentence naming what to do, or empty.
  virtual std::string refusal() const { return {}; }
  virtual LinkHealth health() const { return {}; }
  // Where the device stands across the road (mm from the centre, as it believes it) before it
  // has reported it, when the link knows: a simulated car, where it was put. A real car tells
  // its offset only in its localization updates, which come once it drives: nullopt.
  virtual std::optional<double> knownOffset() const { return std::nullopt; }

  // The frame that stops the device, from its model (docs/safety.md "A stop that does not need
  // the loop"): a link that writes through a socket of its own registers it with that socket
  // (engine/core/emergency_stops.hpp) whenever the socket is open, so the watchdog and the
  // last-resort exit can stop the device without the loop. Others ignore it.
  virtual void setEmergencyStop(std::span<const std::uint8_t> frame) { (void)frame; }

  void onFrame(FrameHandler h) { frameHandler_ = std::move(h); }
  void onState(StateHandler h) { stateHandler_ = std::move(h); }

 protected:
  void deliverFrame(std::span<const std::uint8_t> f) {
    if (frameHandler_) frameHandler_(f);
  }
  void deliverState(bool up, const std::string& reason) {
    if (stateHandler_) stateHandler_(up, reason);
  }

 private:
  FrameHandler frameHandler_;
  StateHandler stateHandler_;
};

}  // namespace pitwall
