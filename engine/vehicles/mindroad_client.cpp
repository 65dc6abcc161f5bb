// The MindRoad client link (../shared/protocols/mindroad.md "Behaviour"; docs/robots.md).
#include "engine/vehicles/mindroad_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/write.hpp>
#include <cstdio>

#include "engine/core/log.hpp"

namespace pitwall {

namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;
using namespace mindroad;

namespace {

constexpr const char* kLog = "mindroad";

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}

std::string range(const std::string& what, long long v, long long min, long long max) {
  return what + " " + std::to_string(v) + " is out of range " + std::to_string(min) + ".." +
         std::to_string(max);
}

}  // namespace

std::shared_ptr<MindroadClient> MindroadClient::create(Loop& loop, MindroadOptions options) {
  return std::shared_ptr<MindroadClient>(new MindroadClient(loop, std::move(options)));
}

MindroadClient::MindroadClient(Loop& loop, MindroadOptions options)
    : loop_(loop), options_(std::move(options)) {}

MindroadClient::~MindroadClient() {
  cancelTimers();
  boost::system::error_code ignored;
  if (tcp_) tcp_->close(ignored);
  if (udp_) udp_->close(ignored);
}

std::string MindroadClient::address() const {
  return std::string(options_.udp ? "udp " : "tcp ") + options_.host + ":" +
         std::to_string(options_.port);
}

std::string MindroadClient::phaseName() const {
  switch (phase_) {
    case Phase::Idle:
      return "idle";
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

template <class F>
Loop::TimerId MindroadClient::after(double s, F fn) {
  return loop_.after(fromSeconds(s), [weak = weak_from_this(), fn = std::move(fn)] {
    if (auto self = weak.lock(); self && self->phase_ != Phase::Closed) fn(*self);
  });
}

void MindroadClient::cancelTimers() {
  for (auto* t : {&contactTimer_, &contactDeadline_, &pingTimer_, &retryTimer_, &probeTimer_,
                  &probeDeadline_}) {
    if (*t) loop_.cancel(*t);
    *t = 0;
  }
}

void MindroadClient::start() {
  if (phase_ != Phase::Idle) return;
  connect();
}

void MindroadClient::connect() {
  retryTimer_ = 0;
  ++generation_;
  phase_ = Phase::Connecting;
  queue_.clear();
  writing_ = false;
  log::debug(kLog, "connecting to " + address());
  resolver_ = std::make_unique<tcp::resolver>(loop_.io());
  resolver_->async_resolve(
      options_.host, std::to_string(options_.port),
      [self = shared_from_this(), gen = generation_](boost::system::error_code ec,
                                                     tcp::resolver::results_type results) {
        if (gen != self->generation_ || self->phase_ == Phase::Closed) return;
        if (ec || results.empty())
          return self->lose("cannot resolve '" + self->options_.host +
                            "': " + (ec ? ec.message() : std::string("no address")));
        if (self->options_.udp) {
          // UDP has no connection; connect() only fixes the peer, so ICMP errors reach us.
          self->udp_ = std::make_unique<udp::socket>(self->loop_.io());
          auto endpoint = results.begin()->endpoint();
          udp::endpoint peer{endpoint.address(), endpoint.port()};
          boost::system::error_code e2;
          self->udp_->open(peer.protocol(), e2);
          if (!e2) self->udp_->connect(peer, e2);
          if (e2) return self->lose("cannot open " + self->address() + ": " + e2.message());
          return self->linkUp();
        }
        self->tcp_ = std::make_unique<tcp::socket>(self->loop_.io());
        asio::async_connect(
            *self->tcp_, results, [self, gen](boost::system::error_code e3, const tcp::endpoint&) {
              if (gen != self->generation_ || self->phase_ == Phase::Closed) return;
              if (e3)
                return self->lose("cannot connect to " + self->address() + ": " + e3.message());
              boost::system::error_code ignored;
              self->tcp_->set_option(tcp::no_delay(true), ignored);
              self->linkUp();
            });
      });
}

void MindroadClient::linkUp() {
  phase_ = Phase::Handshake;
  log::debug(kLog, address() + ": link up, sending contact until the robot answers K");
  read();
  const auto sentBefore = contactsSent_;
  contactDeadline_ = after(options_.contactTimeout, [sentBefore](MindroadClient& c) {
    c.contactDeadline_ = 0;
    c.lose("no contact answer (K) from " + c.address() + " within " +
           seconds(c.options_.contactTimeout) + " (" +
           std::to_string(c.contactsSent_ - sentBefore) + " contact instructions sent)");
  });
  sendContact();
}

void MindroadClient::sendContact() {
  contactTimer_ = 0;
  if (phase_ != Phase::Handshake) return;
  ++contactsSent_;
  write(encode(Contact{}));
  contactTimer_ = after(options_.contactInterval, [](MindroadClient& c) { c.sendContact(); });
}

void MindroadClient::contactAnswered() {
  if (phase_ == Phase::Contact) {  // the answer to a probe (or a late one to the handshake)
    if (probeDeadline_) loop_.cancel(probeDeadline_);
    probeDeadline_ = 0;
    return;
  }
  if (phase_ != Phase::Handshake) return;
  for (auto* t : {&contactTimer_, &contactDeadline_}) {
    if (*t) loop_.cancel(*t);
    *t = 0;
  }
  phase_ = Phase::Contact;
  backoff_ = 0;
  lostReported_ = false;
  lastError_.clear();
  ++contactCount_;
  log::info(kLog, address() + ": contact");
  pingTimer_ = after(options_.watchdog / 3, [](MindroadClient& c) { c.keepAlive(); });
  if (options_.probeInterval > 0)
    probeTimer_ = after(options_.probeInterval, [](MindroadClient& c) { c.probe(); });
  if (auto callback = onContact) callback();  // a copy: the callback may close() us
}

void MindroadClient::keepAlive() {
  pingTimer_ = 0;
  if (phase_ != Phase::Contact) return;
  if (!keepAlivePaused_) write(encode(Ping{}));
  pingTimer_ = after(options_.watchdog / 3, [](MindroadClient& c) { c.keepAlive(); });
}

void MindroadClient::probe() {
  probeTimer_ = 0;
  if (phase_ != Phase::Contact) return;
  if (!keepAlivePaused_ && !probeDeadline_) {
    ++contactsSent_;
    write(encode(Contact{}));
    probeDeadline_ = after(options_.contactTimeout, [](MindroadClient& c) {
      c.probeDeadline_ = 0;
      c.lose(c.address() + " stopped answering: no K to a contact probe within " +
             seconds(c.options_.contactTimeout));
    });
  }
  probeTimer_ = after(options_.probeInterval, [](MindroadClient& c) { c.probe(); });
}

void MindroadClient::read() {
  auto handler = [self = shared_from_this(), gen = generation_](boost::system::error_code ec,
                                                                std::size_t n) {
    if (gen != self->generation_ || self->phase_ == Phase::Closed) return;
    if (ec) {
      if (ec == asio::error::eof) return self->lose(self->address() + " closed the connection");
      return self->lose("lost " + self->address() + ": " + ec.message());
    }
    for (std::size_t i = 0; i < n; ++i) {
      auto answer = decodeAnswer({&self->in_[i], 1});
      if (answer)
        self->contactAnswered();
      else
        log::warn(kLog, self->address() + ": " + answer.error().message() + "; ignored");
      if (gen != self->generation_ || self->phase_ == Phase::Closed) return;  // a handler acted
    }
    self->read();
  };
  if (tcp_)
    tcp_->async_read_some(asio::buffer(in_), std::move(handler));
  else
    udp_->async_receive(asio::buffer(in_), std::move(handler));
}

void MindroadClient::lose(const std::string& reason) {
  if (phase_ == Phase::Closed) return;
  const bool hadContact = phase_ == Phase::Contact;
  ++generation_;
  cancelTimers();
  boost::system::error_code ignored;
  if (tcp_) tcp_->close(ignored);
  if (udp_) udp_->close(ignored);
  queue_.clear();
  writing_ = false;
  lastError_ = reason;
  if (shutdownSent_) {
    phase_ = Phase::Closed;
    lastError_ += " (after shutdown: not reconnecting)";
    log::info(kLog, lastError_);
    if (auto callback = onLost) callback(lastError_);
    onContact = nullptr;
    onLost = nullptr;
    return;
  }
  phase_ = Phase::Waiting;
  backoff_ = backoff_ == 0 ? options_.backoffFirst : std::min(backoff_ * 2, options_.backoffMax);
  const std::string next = "; retrying in " + seconds(backoff_);
  if (hadContact || !lostReported_)
    log::warn(kLog, reason + next);
  else
    log::debug(kLog, reason + next);
  retryTimer_ = after(backoff_, [](MindroadClient& c) { c.connect(); });
  if (!lostReported_) {
    lostReported_ = true;
    if (auto callback = onLost) callback(reason);
  }
}

void MindroadClient::write(const Frame& frame) {
  ++instructionsSent_;
  queue_.push_back(frame);
  if (!writing_) writeNext();
}

void MindroadClient::writeNext() {
  if (queue_.empty()) {
    writing_ = false;
    return;
  }
  writing_ = true;
  auto handler = [self = shared_from_this(), gen = generation_](boost::system::error_code ec,
                                                                std::size_t) {
    if (gen != self->generation_ || self->phase_ == Phase::Closed) return;
    if (ec) return self->lose("lost " + self->address() + " while sending: " + ec.message());
    self->queue_.pop_front();
    self->writeNext();
  };
  const Frame& f = queue_.front();
  if (tcp_)
    asio::async_write(*tcp_, asio::buffer(f.bytes.data(), f.length), std::move(handler));
  else
    udp_->async_send(asio::buffer(f.bytes.data(), f.length), std::move(handler));
}

void MindroadClient::close() {
  if (phase_ == Phase::Closed) return;
  // Best effort: tell the robot to stop now rather than when its watchdog fires. A one-byte
  // send on a non-blocking socket: never waits.
  if (phase_ == Phase::Contact || phase_ == Phase::Handshake) {
    const std::uint8_t stopByte = encode(Stop{}).bytes[0];
    boost::system::error_code ignored;
    if (tcp_ && tcp_->is_open() && queue_.empty()) {
      tcp_->non_blocking(true, ignored);
      tcp_->send(asio::buffer(&stopByte, 1), 0, ignored);
    } else if (udp_ && udp_->is_open()) {
      udp_->non_blocking(true, ignored);
      udp_->send(asio::buffer(&stopByte, 1), 0, ignored);
    }
  }
  phase_ = Phase::Closed;
  ++generation_;
  cancelTimers();
  boost::system::error_code ignored;
  if (resolver_) resolver_->cancel();
  if (tcp_) tcp_->close(ignored);
  if (udp_) udp_->close(ignored);
  queue_.clear();
  onContact = nullptr;
  onLost = nullptr;
  log::debug(kLog, address() + ": closed");
}

MindroadClient::Sent MindroadClient::send(const Instruction& instruction) {
  if (auto bad = validate(instruction)) return Unexpected{*bad + "; nothing sent"};
  const bool linkUp = phase_ == Phase::Contact || phase_ == Phase::Handshake;
  const bool needsContact =
      !std::holds_alternative<Stop>(instruction) && !std::holds_alternative<Contact>(instruction);
  if (phase_ == Phase::Closed)
    return Unexpected{"mindroad " + address() + " is closed; nothing sent"};
  if (needsContact ? phase_ != Phase::Contact : !linkUp) {
    std::string why = phaseName();
    if (!lastError_.empty()) why += ": " + lastError_;
    return Unexpected{"mindroad " + address() + " has no contact (" + why + "); " +
                      std::string(name(instruction)) + " not sent"};
  }
  write(encode(instruction));
  return true;
}

MindroadClient::Sent MindroadClient::steer(long long x, long long y) {
  if (x < -128 || x > 127)
    return Unexpected{range("steer x (forward/backward)", x, -128, 127) + "; nothing sent"};
  if (y < -128 || y > 127)
    return Unexpected{range("steer y (right/left)", y, -128, 127) + "; nothing sent"};
  return send(Steering{static_cast<std::int8_t>(x), static_cast<std::int8_t>(y)});
}

MindroadClient::Sent MindroadClient::click(long long x, long long y) {
  if (x < kClickMinX || x > kClickMaxX)
    return Unexpected{range("click x", x, kClickMinX, kClickMaxX) + "; nothing sent"};
  if (y < kClickMinY || y > kClickMaxY)
    return Unexpected{range("click y", y, kClickMinY, kClickMaxY) + "; nothing sent"};
  return send(MousePosition{static_cast<std::uint8_t>(x), static_cast<std::uint8_t>(y)});
}

MindroadClient::Sent MindroadClient::buttons(long long raw) {
  if (raw < 0 || raw > 255)
    return Unexpected{range("buttons byte", raw, 0, 255) + "; nothing sent"};
  return send(Buttons{static_cast<std::uint8_t>(raw)});
}

MindroadClient::Sent MindroadClient::pictureMode(const std::string& mode) {
  auto p = pictureFromName(mode);
  if (!p)
    return Unexpected{"picture mode '" + mode +
                      "' is unknown; use rgb, hsv or filter; nothing sent"};
  return send(PictureMode{*p});
}

MindroadClient::Sent MindroadClient::stop() {
  return send(Stop{});
}
MindroadClient::Sent MindroadClient::shutdown() {
  auto sent = send(Shutdown{});
  if (sent) shutdownSent_ = true;
  return sent;
}
MindroadClient::Sent MindroadClient::ping() {
  return send(Ping{});
}

}  // namespace pitwall
