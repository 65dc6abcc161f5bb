// A TCP or UDP link on the engine loop (socket_link.hpp).
#include "engine/transport/socket_link.hpp"

#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/write.hpp>
#include <cerrno>
#include <deque>
#include <optional>
#include <vector>

#include "engine/core/emergency_stops.hpp"
#include "engine/core/numbers.hpp"

namespace pitwall {

namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;

namespace {
// A peer that goes away shows as the end of the stream (it closed: FIN), as a reset (it closed
// with data of ours unread, or its process died: RST — which of the two depends only on whether
// our last bytes had been read), or, to a write after either, as a broken pipe. Each is the peer
// closing the connection, and is said so the same way.
bool peerClosed(const boost::system::error_code& ec) {
  return ec == asio::error::eof || ec == asio::error::connection_reset ||
         ec == asio::error::broken_pipe || ec == asio::error::connection_aborted;
}
}  // namespace

// Everything the asynchronous handlers touch lives here, shared with them: a handler that runs
// after the link was closed (or destroyed), or that belongs to an earlier connection, finds
// `closed` set or another `attempt` and does nothing.
struct SocketLink::State : std::enable_shared_from_this<SocketLink::State> {
  State(Loop& l, SocketLinkOptions o) : loop(l), options(std::move(o)), resolver(l.io()) {}

  Loop& loop;
  SocketLinkOptions options;
  tcp::resolver resolver;
  std::unique_ptr<tcp::socket> tcpSocket;
  std::unique_ptr<udp::socket> udpSocket;
  std::array<std::uint8_t, 2048> buffer{};
  std::vector<std::uint8_t> pending;  // received, not yet framed
  std::deque<std::vector<std::uint8_t>> queue;
  bool up = false, closed = false, connecting = false;
  std::uint64_t attempt = 0;  // which attempt the pending handlers belong to
  std::size_t attempts = 0;
  double backoff = 0, backoffBeforeUp = 0;
  std::optional<Loop::TimerId> timer;  // connect timeout or retry
  std::string reason = "connecting";   // why it is not up
  SocketLink* link = nullptr;

  bool isUdp() const { return options.protocol == SocketLinkOptions::Protocol::Udp; }
  std::string where() const {
    return std::string(isUdp() ? "udp:" : "tcp:") + options.host + ":" +
           std::to_string(options.port);
  }

  void cancelTimer() {
    if (timer) loop.cancel(*timer);
    timer.reset();
  }

  // The stop outside the loop (engine/core/emergency_stops.hpp): the socket's slot while it is
  // up. A TCP slot is busy while the queue holds a frame: a frame goes out whole at once when
  // it can (SocketLink::send), so a queued one is one the kernel took part of, or none of yet.
  std::vector<std::uint8_t> emergencyStop;
  int emergencySlot = -1;
  void registerEmergency() {
    if (emergencySlot >= 0 || !up || emergencyStop.empty()) return;
    int fd = tcpSocket ? tcpSocket->native_handle() : udpSocket ? udpSocket->native_handle() : -1;
    emergencySlot = emergency::add(fd, emergencyStop);
    if (tcpSocket) emergency::setBusy(emergencySlot, !queue.empty());
  }

  void closeSockets() {
    emergency::remove(std::exchange(emergencySlot, -1));
    boost::system::error_code ignored;
    if (tcpSocket) tcpSocket->close(ignored);
    if (udpSocket) udpSocket->close(ignored);
  }

  void connect() {
    if (closed) return;
    connecting = true;
    ++attempts;
    const std::uint64_t mine = ++attempt;
    auto self = shared_from_this();
    if (options.connectTimeout > 0)
      timer = loop.after(fromSeconds(options.connectTimeout), [self, mine] {
        self->timer.reset();
        if (self->closed || mine != self->attempt || !self->connecting) return;
        self->failed(mine, "no connection within " + formatNumber(self->options.connectTimeout) +
                               " s (connect timeout)");
      });
    resolver.async_resolve(
        options.host, std::to_string(options.port),
        [self, mine](boost::system::error_code ec, tcp::resolver::results_type results) {
          if (self->closed || mine != self->attempt) return;
          if (ec || results.empty())
            return self->failed(mine, "cannot resolve '" + self->options.host +
                                          "': " + (ec ? ec.message() : std::string("no address")));
          if (self->isUdp()) return self->openUdp(mine, results.begin()->endpoint());
          self->tcpSocket = std::make_unique<tcp::socket>(self->loop.io());
          asio::async_connect(
              *self->tcpSocket, results,
              [self, mine](boost::system::error_code e2, const tcp::endpoint&) {
                if (self->closed || mine != self->attempt) return;
                if (e2)
                  return self->failed(
                      mine, "cannot connect to " + self->options.peer + ": " + e2.message());
                boost::system::error_code ignored;
                self->tcpSocket->set_option(tcp::no_delay(true), ignored);
                self->established();
              });
        });
  }

  // UDP has no connection; connect() only fixes the peer, so ICMP errors reach us.
  void openUdp(std::uint64_t mine, const tcp::endpoint& endpoint) {
    udpSocket = std::make_unique<udp::socket>(loop.io());
    udp::endpoint peer{endpoint.address(), endpoint.port()};
    boost::system::error_code ec;
    udpSocket->open(peer.protocol(), ec);
    if (!ec) udpSocket->connect(peer, ec);
    if (ec) return failed(mine, "cannot open " + options.peer + ": " + ec.message());
    established();
  }

  void established() {
    cancelTimer();
    connecting = false;
    up = true;
    backoffBeforeUp = backoff;
    backoff = 0;
    reason.clear();
    pending.clear();
    read(attempt);
    if (!queue.empty()) write(attempt);
    registerEmergency();
    if (link) link->deliverState(true, "");
  }

  // An attempt failed or the connection dropped: report (once per outage) and retry later.
  void failed(std::uint64_t mine, const std::string& why) {
    if (closed || mine != attempt) return;
    ++attempt;  // orphan every handler of this connection
    cancelTimer();
    resolver.cancel();
    closeSockets();
    queue.clear();
    connecting = false;
    const bool wasUp = up;
    up = false;
    reason = why;
    backoff = backoff == 0 ? options.backoffFirst : std::min(backoff * 2, options.backoffMax);
    auto self = shared_from_this();
    timer = loop.after(fromSeconds(backoff), [self] {
      self->timer.reset();
      self->connect();
    });
    if (link && (wasUp || attempts == 1)) link->deliverState(false, why);
  }

  void received(std::uint64_t mine, std::size_t n) {
    pending.insert(pending.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
    std::size_t start = 0;
    while (start < pending.size()) {
      std::span<const std::uint8_t> rest(pending.data() + start, pending.size() - start);
      std::size_t length = options.frameLength ? options.frameLength(rest) : rest.size();
      if (length == 0) break;
      length = std::min(length, rest.size());
      start += length;
      if (link) link->deliverFrame(rest.first(length));
      if (closed || mine != attempt) return;  // a handler closed or dropped the link
    }
    pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(start));
  }

  void read(std::uint64_t mine) {
    auto self = shared_from_this();
    auto handler = [self, mine](boost::system::error_code ec, std::size_t n) {
      if (self->closed || mine != self->attempt) return;
      if (ec) {
        if (peerClosed(ec))
          return self->failed(mine, self->options.peer + " closed the connection");
        return self->failed(mine, "lost " + self->options.peer + ": " + ec.message());
      }
      self->received(mine, n);
      if (self->closed || mine != self->attempt) return;
      self->read(mine);
    };
    if (tcpSocket)
      tcpSocket->async_read_some(asio::buffer(buffer), std::move(handler));
    else
      udpSocket->async_receive(asio::buffer(buffer), std::move(handler));
  }

  void write(std::uint64_t mine) {
    auto self = shared_from_this();
    auto handler = [self, mine](boost::system::error_code ec, std::size_t) {
      if (self->closed || mine != self->attempt) return;
      if (peerClosed(ec)) return self->failed(mine, self->options.peer + " closed the connection");
      if (ec)
        return self->failed(mine, "lost " + self->options.peer + " while sending: " + ec.message());
      self->queue.pop_front();
      if (!self->queue.empty()) return self->write(mine);
      emergency::setBusy(self->emergencySlot, false);
    };
    // Asio tries a write at once when nothing else is queued on the socket: a frame sent just
    // before close() is already in the kernel when the socket closes.
    if (tcpSocket)
      asio::async_write(*tcpSocket, asio::buffer(queue.front()), std::move(handler));
    else
      udpSocket->async_send(asio::buffer(queue.front()), std::move(handler));
  }

  void close() {
    if (closed) return;
    closed = true;
    ++attempt;
    cancelTimer();
    resolver.cancel();
    // shutdown sends what the kernel holds before the FIN; frames queued behind are dropped.
    boost::system::error_code ignored;
    if (tcpSocket) tcpSocket->shutdown(tcp::socket::shutdown_both, ignored);
    closeSockets();
    queue.clear();
    up = false;
    reason = "closed";
    link = nullptr;
  }
};

SocketLink::SocketLink(Loop& loop, SocketLinkOptions options)
    : state_(std::make_shared<State>(loop, std::move(options))) {
  state_->link = this;
  state_->connect();  // asynchronous: the first report comes from the loop
}

SocketLink::~SocketLink() {
  state_->close();
}

bool SocketLink::send(std::span<const std::uint8_t> frame) {
  auto& s = *state_;
  if (!s.up) return false;
  const bool idle = s.queue.empty();
  if (idle && s.tcpSocket) {
    // Whole at once when the kernel takes it: then no frame is ever half out while the loop
    // stands, and the watchdog's stop can follow it (registerEmergency).
    ssize_t n = ::send(s.tcpSocket->native_handle(), frame.data(), frame.size(),
                       MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(frame.size())) return true;
    if (n > 0) frame = frame.subspan(static_cast<std::size_t>(n));
    // else an error, which the asynchronous write meets and reports, or a full buffer
  }
  s.queue.emplace_back(frame.begin(), frame.end());
  if (s.tcpSocket) emergency::setBusy(s.emergencySlot, true);
  if (idle) s.write(s.attempt);
  return true;
}

void SocketLink::setEmergencyStop(std::span<const std::uint8_t> frame) {
  auto& s = *state_;
  s.emergencyStop.assign(frame.begin(), frame.end());
  emergency::remove(std::exchange(s.emergencySlot, -1));
  s.registerEmergency();
}

bool SocketLink::connected() const {
  return state_->up;
}

void SocketLink::disconnect() {
  state_->close();
}

void SocketLink::reconnect(const std::string& reason) {
  auto& s = *state_;
  if (s.closed) return;
  if (s.up || s.connecting) s.backoff = s.backoffBeforeUp;  // that connection never helped
  s.failed(s.attempt, reason);
}

std::string SocketLink::address() const {
  return state_->where();
}

std::string SocketLink::refusal() const {
  const auto& s = *state_;
  if (s.up) return "";
  if (s.closed) return s.where() + ": closed";
  return s.where() + ": not connected (" + s.reason + ")";
}

std::optional<double> SocketLink::retryIn() const {
  const auto& s = *state_;
  if (s.closed || s.up || s.connecting) return std::nullopt;
  return s.backoff;
}

const SocketLinkOptions& SocketLink::options() const {
  return state_->options;
}

std::size_t SocketLink::attempts() const {
  return state_->attempts;
}

}  // namespace pitwall
