#pragma once
// How the Alphabot Lua object talks to a robot, whichever way it is reached: WLAN (TCP, the
// packet protocol) or Bluetooth LE (the GATT characteristics through BlueZ). Both carry the same
// requests and responses (engine/protocol/alphabot/messages.hpp).
#include <functional>
#include <string>

#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot {

class RobotLink {
 public:
  virtual ~RobotLink() = default;
  // Queues one request; false (nothing sent) when the link is down. A request the link's
  // protocol cannot carry (Ping over BLE) gives false and an explanation in lastError().
  virtual bool send(const Request& request) = 0;
  virtual bool connected() const = 0;
  virtual void close() = 0;
  virtual std::string address() const = 0;  // "tcp:127.0.0.1:4000", "ble:AA:BB:…"
  virtual std::string lastError() const = 0;

  std::function<void(const Response&)> onResponse;
  // Up, or down with the reason (connection refused, closed by the robot, …).
  std::function<void(bool up, const std::string& reason)> onState;
  // Bytes that did not decode: the codec's error, the link carries on.
  std::function<void(const std::string& error)> onMalformed;
};

}  // namespace pitwall::alphabot
