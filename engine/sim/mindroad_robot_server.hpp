#pragma once
// A simulated MindRoad robot on the network: MindroadRobot behind a TCP listener (any number of
// clients, one after another or at once; each connection has its own framing) or a UDP socket
// (one instruction per datagram, or several back to back), on the engine loop. Answers K to the
// sender of a contact; moves the body every 20 ms of loop time. `pitwall sim-robot mindroad`
// and the tests use it.
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/sim/mindroad_robot.hpp"

namespace pitwall::sim {

struct MindroadServerOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;  // 0: any free port (see port())
  bool udp = false;
  MindroadRobotOptions robot;
};

class MindroadRobotServer {
 public:
  // Throws std::runtime_error naming the address when it cannot listen there.
  MindroadRobotServer(Loop& loop, MindroadServerOptions options);
  ~MindroadRobotServer();
  MindroadRobotServer(const MindroadRobotServer&) = delete;
  MindroadRobotServer& operator=(const MindroadRobotServer&) = delete;

  std::uint16_t port() const { return port_; }
  std::string address() const;  // "127.0.0.1:4000"
  MindroadRobot& robot() { return robot_; }
  std::size_t connections() const;  // open TCP connections
  // Closes the listener and every connection: the robot disappears from the network (its
  // state stays readable).
  void close();

  // After the robot's own onChange: every state change, plus "connected" / "disconnected".
  std::function<void(const std::string& event, const std::string& detail)> onChange;

 private:
  struct Connection;
  void accept();
  void read(const std::shared_ptr<Connection>& c);
  void receiveDatagram();
  void handle(const std::vector<std::uint8_t>& answer, const std::shared_ptr<Connection>& c);
  void tick();
  void report(const std::string& event, const std::string& detail);

  Loop& loop_;
  MindroadServerOptions options_;
  MindroadRobot robot_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::unique_ptr<boost::asio::ip::tcp::acceptor> acceptor_;
  std::unique_ptr<boost::asio::ip::udp::socket> udp_;
  boost::asio::ip::udp::endpoint sender_;
  std::array<std::uint8_t, 64> datagram_{};
  std::vector<std::weak_ptr<Connection>> connections_;
  std::uint16_t port_ = 0;
  Loop::TimerId tick_ = 0;
  bool closed_ = false;
};

}  // namespace pitwall::sim
