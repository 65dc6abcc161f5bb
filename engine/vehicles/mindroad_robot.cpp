// The MindRoad robot's model (../shared/protocols/mindroad.md "Behaviour"; docs/robots.md).
#include "engine/vehicles/mindroad_robot.hpp"

#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/transport/socket_link.hpp"

namespace pitwall {

using namespace mindroad;

namespace {

constexpr const char* kLog = "mindroad";

std::string seconds(double s) {
  return formatNumber(s) + " s";
}

MindroadRobot::Sent refuse(std::string sentence) {
  return Unexpected{std::move(sentence) + "; nothing sent"};
}

}  // namespace

std::unique_ptr<Link> makeMindroadLink(Loop& loop, const MindroadOptions& options) {
  SocketLinkOptions o;
  o.protocol = options.udp ? SocketLinkOptions::Protocol::Udp : SocketLinkOptions::Protocol::Tcp;
  o.host = options.host;
  o.port = options.port;
  o.peer = std::string(options.udp ? "udp " : "tcp ") + options.host + ":" +
           std::to_string(options.port);
  o.connectTimeout = 0;  // the system's: the handshake has its own timeout once connected
  o.backoffFirst = options.backoffFirst;
  o.backoffMax = options.backoffMax;
  o.frameLength = answerLength;
  return std::make_unique<SocketLink>(loop, std::move(o));
}

MindroadRobot::MindroadRobot(Loop& loop, std::unique_ptr<Link> link, MindroadOptions options)
    : loop_(loop), link_(std::move(link)), options_(std::move(options)) {
  link_->onFrame([this](std::span<const std::uint8_t> frame) { received(frame); });
  link_->onState([this](bool up, const std::string& reason) { linkChanged(up, reason); });
  // What close() sends, for the stop that does not need the loop (engine/core/emergency_stops.hpp):
  // sooner than the robot's own watchdog
  link_->setEmergencyStop(encode(Stop{}).span());
  log::debug(kLog, "connecting to " + address());
}

MindroadRobot::~MindroadRobot() {
  cancelTimers();
  link_->onFrame(nullptr);
  link_->onState(nullptr);
  link_->disconnect();
}

std::string MindroadRobot::address() const {
  return std::string(options_.udp ? "udp " : "tcp ") + options_.host + ":" +
         std::to_string(options_.port);
}

std::string MindroadRobot::phaseName() const {
  switch (phase_) {
    case Phase::Connecting:
      return "connecting";
    case Phase::Handshake:
      return "waiting for contact";
    case Phase::Contact:
      return "contact";
    case Phase::Waiting:
      return "reconnecting";
    case Phase::Closed:
      return "closed";
  }
  return "?";
}

// Timers die with the model (cancelTimers in the destructor and on every change of link).
template <class F>
Loop::TimerId MindroadRobot::after(double s, F fn) {
  return loop_.after(fromSeconds(s), [this, fn = std::move(fn)] {
    if (phase_ != Phase::Closed) fn();
  });
}

void MindroadRobot::cancelTimers() {
  for (auto* t : {&contactTimer_, &contactDeadline_, &pingTimer_, &probeTimer_, &probeDeadline_}) {
    if (*t) loop_.cancel(*t);
    *t = 0;
  }
}

void MindroadRobot::linkChanged(bool up, const std::string& reason) {
  if (phase_ == Phase::Closed) return;
  if (!up) return lose(reason);
  cancelTimers();
  phase_ = Phase::Handshake;
  log::debug(kLog, address() + ": link up, sending contact until the robot answers K");
  const auto sentBefore = contactsSent_;
  contactDeadline_ = after(options_.contactTimeout, [this, sentBefore] {
    contactDeadline_ = 0;
    fail("no contact answer (K) from " + address() + " within " + seconds(options_.contactTimeout) +
         " (" + std::to_string(contactsSent_ - sentBefore) + " contact instructions sent)");
  });
  sendContact();
}

void MindroadRobot::received(std::span<const std::uint8_t> frame) {
  auto answer = decodeAnswer(frame);
  if (answer)
    contactAnswered();
  else
    malformedWarnings_.warn(kLog, address() + ": " + answer.error().message() + "; ignored");
}

void MindroadRobot::sendContact() {
  contactTimer_ = 0;
  if (phase_ != Phase::Handshake) return;
  ++contactsSent_;
  write(Contact{});
  contactTimer_ = after(options_.contactInterval, [this] { sendContact(); });
}

void MindroadRobot::contactAnswered() {
  if (phase_ == Phase::Contact) {  // the answer to a probe (or a late one to the handshake)
    if (probeDeadline_) loop_.cancel(probeDeadline_);
    probeDeadline_ = 0;
    return;
  }
  if (phase_ != Phase::Handshake) return;
  cancelTimers();
  phase_ = Phase::Contact;
  lostReported_ = false;
  lastError_.clear();
  ++contactCount_;
  log::info(kLog, address() + ": contact");
  pingTimer_ = after(options_.watchdog / 3, [this] { keepAlive(); });
  if (options_.probeInterval > 0) probeTimer_ = after(options_.probeInterval, [this] { probe(); });
  if (auto callback = onContact) callback();  // a copy: the callback may close() us
}

void MindroadRobot::keepAlive() {
  pingTimer_ = 0;
  if (phase_ != Phase::Contact) return;
  if (!keepAlivePaused_) write(Ping{});
  pingTimer_ = after(options_.watchdog / 3, [this] { keepAlive(); });
}

void MindroadRobot::probe() {
  probeTimer_ = 0;
  if (phase_ != Phase::Contact) return;
  if (!keepAlivePaused_ && !probeDeadline_) {
    ++contactsSent_;
    write(Contact{});
    probeDeadline_ = after(options_.contactTimeout, [this] {
      probeDeadline_ = 0;
      fail(address() + " stopped answering: no K to a contact probe within " +
           seconds(options_.contactTimeout));
    });
  }
  probeTimer_ = after(options_.probeInterval, [this] { probe(); });
}

void MindroadRobot::fail(const std::string& reason) {
  // The link is up but the robot does not answer: drop it; the link reports the drop (lose).
  link_->reconnect(reason);
  if (phase_ == Phase::Handshake || phase_ == Phase::Contact) lose(reason);  // a link that did not
}

void MindroadRobot::lose(const std::string& reason) {
  if (phase_ == Phase::Closed) return;
  const bool hadContact = phase_ == Phase::Contact;
  cancelTimers();
  lastError_ = reason;
  if (shutdownSent_) {
    phase_ = Phase::Closed;
    link_->disconnect();
    lastError_ += " (after shutdown: not reconnecting)";
    log::info(kLog, lastError_);
    auto callback = std::move(onLost);
    onContact = nullptr;
    onLost = nullptr;
    if (callback) callback(lastError_);
    return;
  }
  phase_ = Phase::Waiting;
  const auto retry = link_->retryIn();
  const std::string next = retry ? "; retrying in " + seconds(*retry) : "";
  if (hadContact || !lostReported_)
    log::warn(kLog, reason + next);
  else
    log::debug(kLog, reason + next);
  if (!lostReported_) {
    lostReported_ = true;
    if (auto callback = onLost) callback(reason);
  }
}

bool MindroadRobot::write(const Instruction& instruction) {
  if (!link_->send(encode(instruction).span())) return false;
  ++instructionsSent_;
  return true;
}

void MindroadRobot::close() {
  if (phase_ == Phase::Closed) return;
  // Best effort: tell the robot to stop now rather than when its watchdog fires. The link tries
  // the write at once and flushes it before closing: nothing waits.
  if (phase_ == Phase::Contact || phase_ == Phase::Handshake) link_->send(encode(Stop{}).span());
  phase_ = Phase::Closed;
  cancelTimers();
  link_->disconnect();
  onContact = nullptr;
  onLost = nullptr;
  log::debug(kLog, address() + ": closed");
}

MindroadRobot::Sent MindroadRobot::send(const Instruction& instruction) {
  if (auto bad = validate(instruction)) return refuse(*bad);
  const bool linkUp = phase_ == Phase::Contact || phase_ == Phase::Handshake;
  const bool needsContact =
      !std::holds_alternative<Stop>(instruction) && !std::holds_alternative<Contact>(instruction);
  if (phase_ == Phase::Closed) return refuse("mindroad " + address() + " is closed");
  if (needsContact ? phase_ != Phase::Contact : !linkUp) {
    std::string why = phaseName();
    if (!lastError_.empty()) why += ": " + lastError_;
    return Unexpected{"mindroad " + address() + " has no contact (" + why + "); " +
                      std::string(name(instruction)) + " not sent"};
  }
  if (!write(instruction)) {
    const std::string why = link_->refusal();
    return Unexpected{"mindroad " + address() + ": " + std::string(name(instruction)) +
                      " was not sent: " + (why.empty() ? "the link refused it" : why)};
  }
  return true;
}

MindroadRobot::Sent MindroadRobot::steer(long long x, long long y) {
  if (auto e = checkRange("steer x (forward/backward)", static_cast<double>(x), -128, 127))
    return refuse(*e);
  if (auto e = checkRange("steer y (right/left)", static_cast<double>(y), -128, 127))
    return refuse(*e);
  return send(Steering{static_cast<std::int8_t>(x), static_cast<std::int8_t>(y)});
}

MindroadRobot::Sent MindroadRobot::click(long long x, long long y) {
  if (auto e = checkRange("click x", static_cast<double>(x), kClickMinX, kClickMaxX))
    return refuse(*e);
  if (auto e = checkRange("click y", static_cast<double>(y), kClickMinY, kClickMaxY))
    return refuse(*e);
  return send(MousePosition{static_cast<std::uint8_t>(x), static_cast<std::uint8_t>(y)});
}

MindroadRobot::Sent MindroadRobot::buttons(long long raw) {
  if (auto e = checkRange("buttons byte", static_cast<double>(raw), 0, 255)) return refuse(*e);
  return send(Buttons{static_cast<std::uint8_t>(raw)});
}

MindroadRobot::Sent MindroadRobot::pictureMode(const std::string& mode) {
  auto p = pictureFromName(mode);
  if (!p) return refuse("picture mode '" + mode + "' is unknown; use rgb, hsv or filter");
  return send(PictureMode{*p});
}

MindroadRobot::Sent MindroadRobot::stop() {
  return send(Stop{});
}
MindroadRobot::Sent MindroadRobot::shutdown() {
  auto sent = send(Shutdown{});
  if (sent) shutdownSent_ = true;
  return sent;
}
MindroadRobot::Sent MindroadRobot::ping() {
  return send(Ping{});
}

}  // namespace pitwall
