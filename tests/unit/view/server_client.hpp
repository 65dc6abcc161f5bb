#pragma once
// A browser for the race view's server in tests, on real loopback sockets (server_test.cpp,
// drive_messages_test.cpp): a client run in a thread of its own while the engine's loop runs,
// an HTTP request, and a WebSocket on /ws.
#include <doctest/doctest.h>

#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "engine/core/loop.hpp"
#include "tests/support/run_until.hpp"

namespace pitwall::testing {

// Runs `client(port)` in a thread while `loop` runs; returns when it is done (or after `limit`).
// What the client throws fails the test, on the test's thread.
inline void runClient(Loop& loop, std::uint16_t port,
                      const std::function<void(std::uint16_t port)>& client,
                      Duration limit = std::chrono::seconds(20)) {
  std::atomic<bool> done{false};
  std::string failure;
  std::thread t([&] {
    try {
      client(port);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    done = true;
  });
  runUntil(
      loop, [&] { return done.load(); }, limit);
  t.join();
  CHECK_MESSAGE(failure.empty(), "the client failed: " << failure);
}

// One request on a connection of its own (Connection: close); `extraHeader`, when given, is sent
// as the value of an X-Big header. A response that could not be read has status `unknown`.
inline boost::beast::http::response<boost::beast::http::string_body> httpGet(
    std::uint16_t port, const std::string& target,
    boost::beast::http::verb verb = boost::beast::http::verb::get,
    const std::string& extraHeader = "", const std::string& host = "127.0.0.1") {
  namespace asio = boost::asio;
  namespace beast = boost::beast;
  namespace http = beast::http;
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  std::string req =
      std::string(http::to_string(verb)) + " " + target + " HTTP/1.1\r\nHost: " + host + "\r\n";
  if (!extraHeader.empty()) req += "X-Big: " + extraHeader + "\r\n";
  req += "Connection: close\r\n\r\n";
  beast::error_code wec;
  asio::write(stream.socket(), asio::buffer(req), wec);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  beast::error_code ec;
  http::read(stream, buffer, res, ec);
  if (ec) res.result(http::status::unknown);
  return res;
}

// A page's WebSocket on /ws: handshaken on construction; sends text, reads JSON.
struct WsClient {
  boost::asio::io_context io;
  boost::beast::websocket::stream<boost::asio::ip::tcp::socket> ws{io};
  explicit WsClient(std::uint16_t port) {
    ws.next_layer().connect(
        boost::asio::ip::tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    ws.handshake("127.0.0.1", "/ws");
  }
  // From the loopback address `from` (all of 127/8 is this machine: each a client of its own),
  // on `target` (/ws?code=…), with the given Host and, when not empty, Origin and
  // X-Forwarded-For (as a reverse proxy would add it).
  WsClient(std::uint16_t port, const std::string& from, const std::string& target,
           const std::string& host = "127.0.0.1", const std::string& origin = "",
           const std::string& forwardedFor = "") {
    connectFrom(ws.next_layer(), from, port);
    ws.set_option(boost::beast::websocket::stream_base::decorator(
        [origin, forwardedFor](boost::beast::websocket::request_type& req) {
          if (!origin.empty()) req.set(boost::beast::http::field::origin, origin);
          if (!forwardedFor.empty()) req.set("X-Forwarded-For", forwardedFor);
        }));
    ws.handshake(host, target);
  }
  static void connectFrom(boost::asio::ip::tcp::socket& s, const std::string& from,
                          std::uint16_t port) {
    namespace asio = boost::asio;
    s.open(asio::ip::tcp::v4());
    s.bind(asio::ip::tcp::endpoint(asio::ip::make_address(from), 0));
    s.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }
  void send(const char* text) { send(std::string(text)); }
  void send(const std::string& text) {
    ws.text(true);
    ws.write(boost::asio::buffer(text));
  }
  void send(const nlohmann::json& j) { send(j.dump()); }
  nlohmann::json read() {
    boost::beast::flat_buffer b;
    ws.read(b);
    return nlohmann::json::parse(boost::beast::buffers_to_string(b.data()));
  }
};

}  // namespace pitwall::testing
