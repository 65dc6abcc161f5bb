#include "engine/sim/alphabot_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>
#include <deque>
#include <stdexcept>
#include <vector>

#include "engine/protocol/alphabot/wlan_codec.hpp"

namespace pitwall::sim::alphabot {

namespace asio = boost::asio;
using asio::ip::tcp;
namespace wlan = pitwall::alphabot::wlan;

namespace {
constexpr double kStep = 0.02;  // s of loop time per physics step
}

struct Client : std::enable_shared_from_this<Client> {
  explicit Client(tcp::socket s) : socket(std::move(s)) {}
  tcp::socket socket;
  wlan::StreamDecoder decoder{wlan::StreamDecoder::Accept::Requests};
  std::array<std::uint8_t, 512> buffer{};
  std::deque<std::vector<std::uint8_t>> queue;
  bool open = true;
  std::string peer;
};

struct RobotServer::State : std::enable_shared_from_this<RobotServer::State> {
  State(Loop& l, Robot& r) : loop(l), robot(r), acceptor(l.io()) {}
  Loop& loop;
  Robot& robot;
  tcp::acceptor acceptor;
  std::vector<std::shared_ptr<Client>> clients;
  std::optional<Loop::TimerId> tick;
  bool closed = false;
  std::size_t malformed = 0;
  std::size_t requests = 0;
  std::function<void(const std::string&)>* onLog = nullptr;

  void log(const std::string& line) {
    if (onLog && *onLog) (*onLog)(line);
  }

  void accept() {
    acceptor.async_accept([self = shared_from_this()](boost::system::error_code ec, tcp::socket s) {
      if (self->closed) return;
      if (!ec) {
        auto c = std::make_shared<Client>(std::move(s));
        boost::system::error_code pe;
        auto ep = c->socket.remote_endpoint(pe);
        c->peer = pe ? "?" : ep.address().to_string() + ":" + std::to_string(ep.port());
        c->socket.set_option(tcp::no_delay(true), pe);
        self->clients.push_back(c);
        self->log("client " + c->peer + " connected");
        self->read(c);
      }
      self->accept();
    });
  }

  void drop(const std::shared_ptr<Client>& c, const std::string& why) {
    if (!c->open) return;
    c->open = false;
    boost::system::error_code ignored;
    c->socket.close(ignored);
    std::erase(clients, c);
    log("client " + c->peer + " left: " + why);
  }

  void read(const std::shared_ptr<Client>& c) {
    c->socket.async_read_some(
        asio::buffer(c->buffer),
        [self = shared_from_this(), c](boost::system::error_code ec, std::size_t n) {
          if (self->closed || !c->open) return;
          if (ec) {
            self->drop(c, ec == asio::error::eof ? "closed the connection" : ec.message());
            return;
          }
          c->decoder.feed(std::span<const std::uint8_t>(c->buffer.data(), n));
          while (auto packet = c->decoder.next()) {
            if (!*packet) {
              ++self->malformed;
              self->log("malformed request from " + c->peer + ": " + packet->error().message());
              continue;
            }
            if (auto* request = std::get_if<pitwall::alphabot::Request>(&**packet)) {
              ++self->requests;
              self->robot.receive(*request);
            }
            if (self->closed || !c->open) return;
          }
          self->read(c);
        });
  }

  void broadcast(const pitwall::alphabot::Response& response) {
    auto bytes = wlan::encode(response);
    if (!bytes) return;
    for (auto& c : std::vector(clients)) {
      bool idle = c->queue.empty();
      c->queue.push_back(*bytes);
      if (idle) write(c);
    }
  }

  void write(const std::shared_ptr<Client>& c) {
    asio::async_write(c->socket, asio::buffer(c->queue.front()),
                      [self = shared_from_this(), c](boost::system::error_code ec, std::size_t) {
                        if (self->closed || !c->open) return;
                        if (ec) {
                          self->drop(c, ec.message());
                          return;
                        }
                        c->queue.pop_front();
                        if (!c->queue.empty()) self->write(c);
                      });
  }

  void schedule() {
    tick = loop.after(fromSeconds(kStep), [self = shared_from_this()] {
      self->tick.reset();
      if (self->closed) return;
      self->robot.step(kStep);
      self->schedule();
    });
  }

  void close() {
    if (closed) return;
    closed = true;
    if (tick) loop.cancel(*tick);
    tick.reset();
    boost::system::error_code ignored;
    acceptor.close(ignored);
    for (auto& c : std::vector(clients)) {
      c->open = false;
      c->socket.close(ignored);
    }
    clients.clear();
    robot.emit = nullptr;
  }
};

RobotServer::RobotServer(Loop& loop, Robot& robot, const std::string& host, std::uint16_t port)
    : state_(std::make_shared<State>(loop, robot)) {
  state_->onLog = &onLog;
  boost::system::error_code ec;
  auto address = asio::ip::make_address(host, ec);
  if (ec) throw std::runtime_error("cannot listen on '" + host + "': not an IP address");
  tcp::endpoint endpoint(address, port);
  auto& a = state_->acceptor;
  a.open(endpoint.protocol(), ec);
  if (!ec) a.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (!ec) a.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    throw std::runtime_error("cannot listen on " + host + ":" + std::to_string(port) + ": " +
                             ec.message());
  robot.emit = [s = state_.get()](const pitwall::alphabot::Response& r) { s->broadcast(r); };
  state_->accept();
  state_->schedule();
}

RobotServer::~RobotServer() {
  close();
}

void RobotServer::close() {
  state_->close();
  state_->onLog = nullptr;
}

std::uint16_t RobotServer::port() const {
  boost::system::error_code ec;
  auto ep = state_->acceptor.local_endpoint(ec);
  return ec ? 0 : ep.port();
}

std::size_t RobotServer::clients() const {
  return state_->clients.size();
}

std::size_t RobotServer::requests() const {
  return state_->requests;
}

std::size_t RobotServer::malformed() const {
  return state_->malformed;
}

}  // namespace pitwall::sim::alphabot
