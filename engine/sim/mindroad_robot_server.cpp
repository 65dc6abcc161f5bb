#include "engine/sim/mindroad_robot_server.hpp"

#include <boost/asio/ip/address.hpp>
#include <boost/asio/write.hpp>
#include <stdexcept>

namespace pitwall::sim {

namespace asio = boost::asio;
using asio::ip::tcp;
using asio::ip::udp;

namespace {
constexpr auto kTick = std::chrono::milliseconds(20);
}

struct MindroadRobotServer::Connection {
  explicit Connection(asio::io_context& io) : socket(io) {}
  tcp::socket socket;
  std::array<std::uint8_t, 256> buffer{};
  mindroad::StreamDecoder decoder;
  std::string peer;
};

MindroadRobotServer::MindroadRobotServer(Loop& loop, MindroadServerOptions options)
    : loop_(loop), options_(std::move(options)), robot_(options_.robot) {
  robot_.onChange = [this](const std::string& event, const std::string& detail) {
    report(event, detail);
  };
  boost::system::error_code ec;
  auto address = asio::ip::make_address(options_.host, ec);
  if (ec)
    throw std::runtime_error("cannot listen on '" + options_.host +
                             "': not an IP address (use e.g. 127.0.0.1 or 0.0.0.0)");
  const std::string where = options_.host + ":" + std::to_string(options_.port);
  if (options_.udp) {
    udp_ = std::make_unique<udp::socket>(loop_.io());
    udp_->open(address.is_v6() ? udp::v6() : udp::v4(), ec);
    if (!ec) udp_->bind({address, options_.port}, ec);
    if (ec) throw std::runtime_error("cannot listen on udp " + where + ": " + ec.message());
    port_ = udp_->local_endpoint().port();
    receiveDatagram();
  } else {
    acceptor_ = std::make_unique<tcp::acceptor>(loop_.io());
    tcp::endpoint endpoint{address, options_.port};
    acceptor_->open(endpoint.protocol(), ec);
    if (!ec) acceptor_->set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor_->bind(endpoint, ec);
    if (!ec) acceptor_->listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw std::runtime_error("cannot listen on tcp " + where + ": " + ec.message());
    port_ = acceptor_->local_endpoint().port();
    accept();
  }
  tick_ = loop_.after(kTick, [this, alive = std::weak_ptr<bool>(alive_)] {
    if (!alive.expired()) tick();
  });
}

MindroadRobotServer::~MindroadRobotServer() {
  alive_.reset();
  close();
  if (tick_) loop_.cancel(tick_);
}

std::string MindroadRobotServer::address() const {
  return options_.host + ":" + std::to_string(port_);
}

std::size_t MindroadRobotServer::connections() const {
  std::size_t n = 0;
  for (const auto& w : connections_)
    if (auto c = w.lock(); c && c->socket.is_open()) ++n;
  return n;
}

void MindroadRobotServer::close() {
  if (closed_) return;
  closed_ = true;
  boost::system::error_code ignored;
  if (acceptor_) acceptor_->close(ignored);
  if (udp_) udp_->close(ignored);
  for (const auto& w : connections_)
    if (auto c = w.lock()) c->socket.close(ignored);
  connections_.clear();
}

void MindroadRobotServer::report(const std::string& event, const std::string& detail) {
  if (onChange) onChange(event, detail);
}

void MindroadRobotServer::tick() {
  robot_.advance(loop_.seconds());
  tick_ = loop_.after(kTick, [this, alive = std::weak_ptr<bool>(alive_)] {
    if (!alive.expired()) tick();
  });
}

void MindroadRobotServer::accept() {
  auto c = std::make_shared<Connection>(loop_.io());
  acceptor_->async_accept(
      c->socket, [this, c, alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec) {
        if (alive.expired() || closed_) return;
        if (!ec) {
          boost::system::error_code e2;
          auto peer = c->socket.remote_endpoint(e2);
          c->peer = e2 ? "?" : peer.address().to_string() + ":" + std::to_string(peer.port());
          connections_.push_back(c);
          report("connected", "client " + c->peer + " connected");
          read(c);
        }
        accept();
      });
}

void MindroadRobotServer::read(const std::shared_ptr<Connection>& c) {
  c->socket.async_read_some(
      asio::buffer(c->buffer),
      [this, c, alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec, std::size_t n) {
        if (alive.expired() || closed_) return;
        if (ec) {
          boost::system::error_code ignored;
          c->socket.close(ignored);
          report("disconnected",
                 "client " + c->peer + " disconnected (" +
                     (ec == asio::error::eof ? std::string("closed") : ec.message()) + ")");
          return;
        }
        for (const auto& in : c->decoder.feed({c->buffer.data(), n})) {
          auto answer = robot_.receive(in, loop_.seconds());
          if (!answer.empty()) handle(answer, c);
          if (robot_.state().shutdown) return;
        }
        read(c);
      });
}

void MindroadRobotServer::handle(const std::vector<std::uint8_t>& answer,
                                 const std::shared_ptr<Connection>& c) {
  auto data = std::make_shared<std::vector<std::uint8_t>>(answer);
  asio::async_write(c->socket, asio::buffer(*data),
                    [data, c](boost::system::error_code, std::size_t) {});
}

void MindroadRobotServer::receiveDatagram() {
  udp_->async_receive_from(
      asio::buffer(datagram_), sender_,
      [this, alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec, std::size_t n) {
        if (alive.expired() || closed_) return;
        if (!ec) {
          // A datagram holds whole instructions: what its headers leave over is malformed.
          mindroad::StreamDecoder decoder;
          auto results = decoder.feed({datagram_.data(), n});
          if (decoder.pending() > 0)
            results.push_back(mindroad::decode(std::span<const std::uint8_t>(
                datagram_.data() + n - decoder.pending(), decoder.pending())));
          for (const auto& in : results) {
            auto answer = robot_.receive(in, loop_.seconds());
            if (!answer.empty()) {
              auto data = std::make_shared<std::vector<std::uint8_t>>(answer);
              udp_->async_send_to(asio::buffer(*data), sender_,
                                  [data](boost::system::error_code, std::size_t) {});
            }
            if (robot_.state().shutdown) return;
          }
        }
        // Errors on an unconnected UDP socket (an ICMP answer to an earlier send) are not
        // fatal: keep receiving.
        receiveDatagram();
      });
}

}  // namespace pitwall::sim
