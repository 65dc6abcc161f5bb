#pragma once
// An Alphabot reached over WLAN: the packet protocol (wlan_codec.hpp) on a TCP connection, on the
// engine's one loop. It connects at once (each attempt bounded by a timeout), and whenever the
// connection fails or drops it tries again after a backoff of 0.5 s, doubling to 8 s, reset by
// a connection that comes up. onState reports up, and down with the reason, once per change.
//
// Malformed bytes from the robot are reported through onMalformed and skipped as the stream
// decoder resynchronises (to the next byte that is a response id); the connection stays up.
// Loop timers are real-time timers here: a TCP robot needs a real clock (not --fast).
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"
#include "engine/vehicles/alphabot_link.hpp"

namespace pitwall::alphabot {

struct TcpLinkOptions {
  double connectTimeout = 3.0;  // s per attempt
  double backoffFirst = 0.5;    // s before the first retry
  double backoffMax = 8.0;      // s, the cap of the doubling
  wlan::Options codec;
};

class TcpRobotLink : public RobotLink {
 public:
  TcpRobotLink(Loop& loop, std::string host, std::uint16_t port, TcpLinkOptions options = {});
  ~TcpRobotLink() override;

  bool send(const Request& request) override;
  bool connected() const override;
  void close() override;
  std::string address() const override;
  std::string lastError() const override;
  std::size_t attempts() const;  // connection attempts so far (tests, logs)

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace pitwall::alphabot
