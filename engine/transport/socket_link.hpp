#pragma once
// A link to a device on the network: TCP (a byte stream) or UDP (datagrams to one peer), on the
// engine's one loop (Boost.Asio). It connects when made, each attempt bounded by a connect
// timeout, and whenever an attempt fails or the connection drops it tries again after a backoff
// of 0.5 s doubling to 8 s (options), reset by a connection that comes up. The state handler
// hears of each outage once: an up link that drops, or the very first attempt failing; the
// failed attempts of an outage after that are not news. reconnect(reason) is a drop the model
// decided on (a device that does not answer): reported the same way, and the backoff goes on
// doubling from where it was before that connection came up, since it never became useful.
//
// Frames: the protocol's frameLength cuts what arrives into frames (a TCP read may hold half a
// packet or three). Bytes it cannot frame are delivered as one frame all the same, for the
// model to fail to decode and report as malformed. UDP has no connection: "up" means the socket
// is open towards the peer; an ICMP error from the peer's host (port unreachable) is a drop.
//
// Sentences name the other end as `peer` ("the robot", "tcp 127.0.0.1:4000"). A device over TCP
// or UDP needs the real clock: virtual time races past the timeouts of a real socket.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/transport/link.hpp"

namespace pitwall {

// How many bytes from the start of `pending` (bytes received, not yet framed) make the next
// frame; 0 when more bytes are needed. Given by the protocol (a pure function of the bytes).
using FrameLength = std::function<std::size_t(std::span<const std::uint8_t> pending)>;

struct SocketLinkOptions {
  enum class Protocol { Tcp, Udp };
  Protocol protocol = Protocol::Tcp;
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;
  std::string peer = "the device";  // the other end, as sentences name it
  double connectTimeout = 3.0;      // s per attempt; 0: the system's own
  double backoffFirst = 0.5;        // s before the first retry…
  double backoffMax = 8.0;          // …doubling up to this
  FrameLength frameLength;          // empty: every read is one frame
};

class SocketLink : public Link {
 public:
  SocketLink(Loop& loop, SocketLinkOptions options);
  ~SocketLink() override;
  SocketLink(const SocketLink&) = delete;
  SocketLink& operator=(const SocketLink&) = delete;

  bool send(std::span<const std::uint8_t> frame) override;
  // The stop the watchdog sends on the socket itself (engine/core/emergency_stops.hpp).
  void setEmergencyStop(std::span<const std::uint8_t> frame) override;
  bool connected() const override;
  // Closes for good: what was just sent is flushed before the close (a stop sent before
  // disconnect() reaches the device); no reconnection, no more handlers.
  void disconnect() override;
  void reconnect(const std::string& reason) override;
  std::string address() const override;  // "tcp:127.0.0.1:4000", "udp:…"
  std::string refusal() const override;  // "tcp:…: not connected (why)", "tcp:…: closed"
  std::optional<double> retryIn() const override;  // s, while waiting to try again

  const SocketLinkOptions& options() const;
  std::size_t attempts() const;  // connection attempts so far (tests, logs)

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace pitwall
