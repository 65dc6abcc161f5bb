#pragma once
// The simulated Alphabot on the network: a TCP server speaking the WLAN packet protocol
// (wlan_codec.hpp) for a Robot, on the engine loop. Every client may send requests; every
// response goes to every connected client. The robot's physics step every 20 ms of loop time.
// A malformed request is logged and skipped (the stream resynchronises, wlan_codec.hpp); the
// connection stays up.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/sim/alphabot_robot.hpp"

namespace pitwall::sim::alphabot {

class RobotServer {
 public:
  // Listens on host:port (port 0: a free port). Throws std::runtime_error naming the address
  // when it cannot listen.
  RobotServer(Loop& loop, Robot& robot, const std::string& host, std::uint16_t port);
  ~RobotServer();
  RobotServer(const RobotServer&) = delete;
  RobotServer& operator=(const RobotServer&) = delete;

  std::uint16_t port() const;
  std::size_t clients() const;
  std::size_t malformed() const;
  std::size_t requests() const;  // well-formed requests received (all clients)
  // Stops listening and drops every client (a robot that disappears).
  void close();

  // Log lines: client connected/left, malformed requests.
  std::function<void(const std::string&)> onLog;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace pitwall::sim::alphabot
