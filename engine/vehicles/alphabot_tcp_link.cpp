#include "engine/vehicles/alphabot_tcp_link.hpp"

#include <algorithm>
#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <cstdio>
#include <deque>
#include <vector>

namespace pitwall::alphabot {

namespace asio = boost::asio;
using asio::ip::tcp;

// Everything the asynchronous handlers touch lives here, shared with them: a handler that runs
// after the link was closed (or destroyed) finds `closed` set and does nothing.
struct TcpRobotLink::State : std::enable_shared_from_this<TcpRobotLink::State> {
  State(Loop& l, std::string h, std::uint16_t p, TcpLinkOptions o)
      : loop(l),
        host(std::move(h)),
        port(p),
        options(o),
        resolver(l.io()),
        socket(l.io()),
        decoder(wlan::StreamDecoder::Accept::Responses, o.codec) {}

  Loop& loop;
  std::string host;
  std::uint16_t port;
  TcpLinkOptions options;
  tcp::resolver resolver;
  tcp::socket socket;
  wlan::StreamDecoder decoder;
  std::array<std::uint8_t, 1024> buffer{};
  std::deque<std::vector<std::uint8_t>> queue;
  bool up = false, closed = false, connecting = false;
  std::uint64_t attempt = 0;  // which attempt the pending handlers belong to
  std::size_t attempts = 0;
  double backoff = 0;
  std::optional<Loop::TimerId> timer;  // connect timeout or retry
  std::string reason = "connecting";   // why it is not up
  TcpRobotLink* link = nullptr;

  std::string where() const { return "tcp:" + host + ":" + std::to_string(port); }

  void cancelTimer() {
    if (timer) loop.cancel(*timer);
    timer.reset();
  }

  void connect() {
    if (closed) return;
    connecting = true;
    ++attempts;
    std::uint64_t mine = ++attempt;
    auto self = shared_from_this();
    timer = loop.after(fromSeconds(options.connectTimeout), [self, mine] {
      self->timer.reset();
      if (self->closed || mine != self->attempt || !self->connecting) return;
      char text[64];
      std::snprintf(text, sizeof text, "no connection within %g s (connect timeout)",
                    self->options.connectTimeout);
      self->failed(mine, text);
    });
    resolver.async_resolve(
        host, std::to_string(port),
        [self, mine](boost::system::error_code ec, tcp::resolver::results_type r) {
          if (self->closed || mine != self->attempt) return;
          if (ec) {
            self->failed(mine, "cannot resolve '" + self->host + "': " + ec.message());
            return;
          }
          asio::async_connect(self->socket, r,
                              [self, mine](boost::system::error_code ec2, const tcp::endpoint&) {
                                if (self->closed || mine != self->attempt) return;
                                if (ec2) {
                                  self->failed(mine, ec2.message());
                                  return;
                                }
                                self->established();
                              });
        });
  }

  void established() {
    cancelTimer();
    connecting = false;
    up = true;
    backoff = 0;
    reason.clear();
    decoder.reset();
    boost::system::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);
    read(attempt);
    if (!queue.empty()) write(attempt);
    if (link && link->onState) link->onState(true, "");
  }

  // An attempt failed or the connection dropped: report (once, if it was up) and retry later.
  void failed(std::uint64_t mine, const std::string& reason) {
    if (closed || mine != attempt) return;
    ++attempt;  // orphan every handler of this connection
    cancelTimer();
    resolver.cancel();
    boost::system::error_code ignored;
    socket.close(ignored);
    queue.clear();
    connecting = false;
    bool wasUp = up;
    up = false;
    this->reason = reason;
    backoff = backoff == 0 ? options.backoffFirst : std::min(backoff * 2, options.backoffMax);
    auto self = shared_from_this();
    timer = loop.after(fromSeconds(backoff), [self] {
      self->timer.reset();
      self->connect();
    });
    if (link && link->onState) {
      if (wasUp)
        link->onState(false, reason);
      else if (attempts == 1)
        link->onState(false, reason);  // the first attempt failing is news too
    }
  }

  void read(std::uint64_t mine) {
    auto self = shared_from_this();
    socket.async_read_some(
        asio::buffer(buffer), [self, mine](boost::system::error_code ec, std::size_t n) {
          if (self->closed || mine != self->attempt) return;
          if (ec) {
            self->failed(mine,
                         ec == asio::error::eof ? "the robot closed the connection" : ec.message());
            return;
          }
          self->decoder.feed(std::span<const std::uint8_t>(self->buffer.data(), n));
          while (auto packet = self->decoder.next()) {
            if (!*packet) {
              if (self->link && self->link->onMalformed)
                self->link->onMalformed(packet->error().message());
            } else if (auto* response = std::get_if<Response>(&**packet)) {
              if (self->link && self->link->onResponse) self->link->onResponse(*response);
            }
            if (self->closed || mine != self->attempt) return;  // a callback closed the link
          }
          self->read(mine);
        });
  }

  void write(std::uint64_t mine) {
    auto self = shared_from_this();
    asio::async_write(socket, asio::buffer(queue.front()),
                      [self, mine](boost::system::error_code ec, std::size_t) {
                        if (self->closed || mine != self->attempt) return;
                        if (ec) {
                          self->failed(mine, ec.message());
                          return;
                        }
                        self->queue.pop_front();
                        if (!self->queue.empty()) self->write(mine);
                      });
  }

  void close() {
    if (closed) return;
    closed = true;
    ++attempt;
    cancelTimer();
    resolver.cancel();
    // A request sent just before (the binding's stop on close) is already in the kernel: Asio
    // tries a stream write at once when nothing else is queued, and shutdown sends what the
    // kernel holds before the FIN. Requests queued behind it are dropped.
    boost::system::error_code ignored;
    socket.shutdown(tcp::socket::shutdown_both, ignored);
    socket.close(ignored);
    queue.clear();
    up = false;
    reason = "closed";
    link = nullptr;
  }
};

TcpRobotLink::TcpRobotLink(Loop& loop, std::string host, std::uint16_t port, TcpLinkOptions options)
    : state_(std::make_shared<State>(loop, std::move(host), port, options)) {
  state_->link = this;
  state_->connect();
}

TcpRobotLink::~TcpRobotLink() {
  state_->close();
}

bool TcpRobotLink::send(const Request& request) {
  auto& s = *state_;
  if (!s.up) return false;
  bool idle = s.queue.empty();
  s.queue.push_back(wlan::encode(request, s.options.codec));
  if (idle) s.write(s.attempt);
  return true;
}

bool TcpRobotLink::connected() const {
  return state_->up;
}

void TcpRobotLink::close() {
  state_->close();
}

std::string TcpRobotLink::address() const {
  return state_->where();
}

std::string TcpRobotLink::lastError() const {
  const auto& s = *state_;
  if (s.up) return "";
  if (s.closed) return s.where() + ": closed";
  return s.where() + ": not connected (" + s.reason + ")";
}

std::size_t TcpRobotLink::attempts() const {
  return state_->attempts;
}

}  // namespace pitwall::alphabot
