#pragma once
// The client side of a MindRoad robot car (../shared/protocols/mindroad.md): a TCP (default) or
// UDP link on the engine loop, the contact handshake (contact every 100 ms until K arrives, with
// an overall timeout), keep-alive pings at a third of the watchdog period, and reconnection with
// backoff (0.5 s doubling to 8 s) when the link or the contact is lost. Commands are validated
// here, at the edge: an out-of-range value or a robot without contact gives an error and sends
// nothing.
//
// Lost contact is seen as: TCP end of stream or a socket error; UDP an ICMP error from the
// robot's host (port unreachable); both: a handshake or a contact probe (every second once in
// contact) that gets no K within the contact timeout.
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/protocol/mindroad/codec.hpp"

namespace pitwall {

struct MindroadOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 4000;
  bool udp = false;
  double watchdog = 0.5;         // s; the robot's watchdog period: pings every third of it
  double contactInterval = 0.1;  // s between contact instructions during the handshake
  double contactTimeout = 3;     // s a handshake may take before the attempt counts as failed
  double backoffFirst = 0.5;     // s before the first reconnection attempt; doubles…
  double backoffMax = 8;         // …up to this
  // s between contact probes once in contact (0: none). The robot answers nothing but contact,
  // so a probe is the only way to see a robot that went silent (UDP, a dead host), and it
  // re-establishes contact if the robot's watchdog fired meanwhile. No K within contactTimeout:
  // contact lost.
  double probeInterval = 1;
};

class MindroadClient : public std::enable_shared_from_this<MindroadClient> {
 public:
  using Sent = Result<bool, std::string>;
  enum class Phase { Idle, Connecting, Handshake, Contact, Waiting, Closed };

  static std::shared_ptr<MindroadClient> create(Loop& loop, MindroadOptions options);
  ~MindroadClient();

  // Connects and shakes hands; reconnects by itself until close().
  void start();
  // Sends stop (best effort, without blocking), closes the link, cancels every timer. No event
  // is called afterwards.
  void close();

  // Commands: validated, then sent; an error (nothing sent) names the value and the range, or
  // says why the robot cannot take it now.
  Sent steer(long long x, long long y);
  Sent click(long long x, long long y);
  Sent buttons(long long raw);
  Sent pictureMode(const std::string& mode);
  Sent stop();
  Sent shutdown();  // after it, a lost link is reported and not retried (the robot is off)
  Sent ping();
  // Any instruction (validated); contact and stop go out without contact, the rest need it.
  Sent send(const mindroad::Instruction& instruction);

  bool connected() const { return phase_ == Phase::Contact; }
  Phase phase() const { return phase_; }
  std::string phaseName() const;
  const MindroadOptions& options() const { return options_; }
  std::string address() const;  // "tcp 127.0.0.1:4000" / "udp …"
  const std::string& lastError() const { return lastError_; }
  std::uint64_t contactsSent() const { return contactsSent_; }
  std::uint64_t instructionsSent() const { return instructionsSent_; }
  std::uint64_t contacts() const { return contactCount_; }

  // Tests: stop (or resume) the keep-alive pings and probes, so the robot's watchdog fires.
  void pauseKeepAlive(bool paused) { keepAlivePaused_ = paused; }

  // Contact established (again). Called from the loop, never from inside a command.
  std::function<void()> onContact;
  // Contact lost, or an attempt to get it failed; `reason` is one sentence. Called once per
  // outage (not again for each failed reconnection attempt), from the loop.
  std::function<void(const std::string& reason)> onLost;

 private:
  MindroadClient(Loop& loop, MindroadOptions options);
  void connect();
  void linkUp();
  void sendContact();
  void contactAnswered();
  void keepAlive();
  void probe();
  void read();
  void lose(const std::string& reason);
  void write(const mindroad::Frame& frame);
  void writeNext();
  void cancelTimers();
  template <class F>
  Loop::TimerId after(double seconds, F fn);

  Loop& loop_;
  MindroadOptions options_;
  Phase phase_ = Phase::Idle;
  std::unique_ptr<boost::asio::ip::tcp::socket> tcp_;
  std::unique_ptr<boost::asio::ip::udp::socket> udp_;
  std::unique_ptr<boost::asio::ip::tcp::resolver> resolver_;
  std::array<std::uint8_t, 64> in_{};
  std::deque<mindroad::Frame> queue_;
  bool writing_ = false;
  std::uint64_t generation_ = 0;  // bumps on every new link: stale handlers see a change
  Loop::TimerId contactTimer_ = 0, contactDeadline_ = 0, pingTimer_ = 0, retryTimer_ = 0,
                probeTimer_ = 0, probeDeadline_ = 0;
  double backoff_ = 0;
  bool lostReported_ = false;
  bool keepAlivePaused_ = false;
  bool shutdownSent_ = false;  // the robot was turned off: a lost link is not retried
  std::string lastError_;
  std::uint64_t contactsSent_ = 0, instructionsSent_ = 0, contactCount_ = 0;
};

}  // namespace pitwall
