#pragma once
// The controller-side model of a MindRoad robot car (../shared/protocols/mindroad.md) over a
// link: the contact handshake (contact every 100 ms until K arrives, within contactTimeout),
// keep-alive pings at a third of the watchdog period, contact probes once in contact, validated
// commands, and the phases and counters a user reads. Commands are validated here, at the edge:
// an out-of-range value or a robot without contact gives an error and sends nothing.
//
// The link (TCP by default, UDP as an option: makeMindroadLink) reconnects by itself with its
// backoff (0.5 s doubling to 8 s). Lost contact is seen as: the link dropping (TCP end of stream
// or a socket error; UDP an ICMP error from the robot's host), or a handshake or a contact probe
// (every second once in contact) that gets no K within the contact timeout — then the model asks
// the link to reconnect. onLost is called once per outage.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/core/warning_limit.hpp"
#include "engine/protocol/mindroad/codec.hpp"
#include "engine/transport/link.hpp"

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

// The TCP or UDP link to the robot the options name (engine/transport/socket_link.hpp), framed
// by the robot's one-byte answers; it starts connecting at once.
std::unique_ptr<Link> makeMindroadLink(Loop& loop, const MindroadOptions& options);

class MindroadRobot {
 public:
  using Sent = Result<bool, std::string>;
  enum class Phase { Connecting, Handshake, Contact, Waiting, Closed };

  MindroadRobot(Loop& loop, std::unique_ptr<Link> link, MindroadOptions options);
  ~MindroadRobot();
  MindroadRobot(const MindroadRobot&) = delete;
  MindroadRobot& operator=(const MindroadRobot&) = delete;

  // Sends stop (best effort, without waiting), closes the link, cancels every timer. No event
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
  Link& link() { return *link_; }

  // Tests: stop (or resume) the keep-alive pings and probes, so the robot's watchdog fires.
  void pauseKeepAlive(bool paused) { keepAlivePaused_ = paused; }

  // Contact established (again). Called from the loop, never from inside a command.
  std::function<void()> onContact;
  // Contact lost, or an attempt to get it failed; `reason` is one sentence. Called once per
  // outage (not again for each failed reconnection attempt), from the loop.
  std::function<void(const std::string& reason)> onLost;

 private:
  void linkChanged(bool up, const std::string& reason);
  void received(std::span<const std::uint8_t> frame);
  void sendContact();
  void contactAnswered();
  void keepAlive();
  void probe();
  void fail(const std::string& reason);  // contact failed while the link is up
  void lose(const std::string& reason);  // the link went down
  // Hands the instruction to the link; false (not counted) when the link refused it.
  bool write(const mindroad::Instruction& instruction);
  void cancelTimers();
  template <class F>
  Loop::TimerId after(double seconds, F fn);

  Loop& loop_;
  std::unique_ptr<Link> link_;
  MindroadOptions options_;
  Phase phase_ = Phase::Connecting;
  Loop::TimerId contactTimer_ = 0, contactDeadline_ = 0, pingTimer_ = 0, probeTimer_ = 0,
                probeDeadline_ = 0;
  bool lostReported_ = false;
  bool keepAlivePaused_ = false;
  bool shutdownSent_ = false;  // the robot was turned off: a lost link is not retried
  std::string lastError_;
  std::uint64_t contactsSent_ = 0, instructionsSent_ = 0, contactCount_ = 0;
  // A robot or link that sends only answers that do not decode: the first warned, then a count
  // each 5 s.
  WarningLimit malformedWarnings_{loop_, "answers that do not decode ignored"};
};

}  // namespace pitwall
