// The race view's server on real loopback sockets: files, /api/state, the WebSocket's pace, and
// adversaries — a browser that never reads, hostile requests and messages, a port in use. The
// engine's loop runs here; each client runs in a thread of its own (a browser is another process).
#include <doctest/doctest.h>

#include <unistd.h>
#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <filesystem>
#include <fstream>
#include <thread>

#include "engine/fleet/fleet.hpp"
#include "engine/view/server.hpp"
#include "tests/support/run_until.hpp"
#include "tests/unit/view/server_client.hpp"

using namespace pitwall;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using testing::httpGet;
using testing::runClient;
using testing::runUntil;
using testing::WsClient;

namespace {

struct Assets {
  std::filesystem::path dir;
  Assets() {
    dir = std::filesystem::temp_directory_path() /
          ("pitwall-view-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir / "vendor");
    std::ofstream(dir / "index.html") << "<!doctype html><title>race view</title>";
    std::ofstream(dir / "vendor" / "lib.js") << "// lib";
    std::ofstream(dir.parent_path() / "pitwall-view-secret.txt") << "secret";
  }
  ~Assets() {
    std::filesystem::remove_all(dir);
    std::filesystem::remove(dir.parent_path() / "pitwall-view-secret.txt");
  }
};

struct Rig {
  Assets assets;
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  view::Feed feed{loop, fleet, "simulator"};
  std::unique_ptr<view::Server> server;
  explicit Rig(double rate = 30) {
    view::ServerOptions o;
    o.port = 0;
    o.assets = assets.dir;
    o.maxRate = rate;
    server = std::make_unique<view::Server>(loop, feed, o);
    REQUIRE(server->start());
  }
  // Runs `client` in a thread while the loop runs; returns when it is done (or after `limit`).
  void with(const std::function<void(std::uint16_t port)>& client,
            Duration limit = std::chrono::seconds(20)) {
    runClient(loop, server->port(), client, limit);
  }
};

}  // namespace

TEST_CASE("view server: the page, its assets and /api/state; nothing outside the folder") {
  Rig rig;
  rig.with([](std::uint16_t port) {
    auto page = httpGet(port, "/");
    CHECK(page.result() == http::status::ok);
    CHECK(page.body().find("race view") != std::string::npos);
    CHECK(std::string(page[http::field::content_type]).starts_with("text/html"));
    CHECK(httpGet(port, "/vendor/lib.js").result() == http::status::ok);
    auto state = httpGet(port, "/api/state");
    REQUIRE(state.result() == http::status::ok);
    auto j = nlohmann::json::parse(state.body());
    CHECK(j["type"] == "state");
    CHECK(j["source"] == "simulator");
    CHECK(j["cars"].is_array());
    for (const char* bad :
         {"/../pitwall-view-secret.txt", "/vendor/../../pitwall-view-secret.txt",
          "/%2e%2e/pitwall-view-secret.txt", "//etc/passwd", "/vendor", "/nothing.js", "/a\\b"})
      CHECK_MESSAGE(httpGet(port, bad).result() == http::status::not_found, std::string(bad));
    CHECK(httpGet(port, "/api/state", http::verb::post).result() ==
          http::status::method_not_allowed);
    // a header beyond the limit: refused, and the server goes on
    CHECK(httpGet(port, "/", http::verb::get, std::string(64 * 1024, 'x')).result() !=
          http::status::ok);
    CHECK(httpGet(port, "/api/state").result() == http::status::ok);
  });
}

TEST_CASE("view server: a port in use is refused with what to do; --view's forms") {
  Rig rig;
  view::ServerOptions o;
  o.port = rig.server->port();
  o.assets = rig.assets.dir;
  view::Server second(rig.loop, rig.feed, o);
  auto started = second.start();
  REQUIRE_FALSE(started);
  CHECK(started.error().find("in use") != std::string::npos);
  CHECK(started.error().find("--view") != std::string::npos);
  CHECK(started.error().find(std::to_string(o.port)) != std::string::npos);

  auto def = view::parseEndpoint("");
  REQUIRE(def);
  CHECK(def->host == "127.0.0.1");  // loopback unless another address is given
  CHECK(def->port == view::kDefaultPort);
  CHECK(view::parseEndpoint("9000")->port == 9000);
  CHECK(view::parseEndpoint("9000")->host == "127.0.0.1");
  CHECK(view::parseEndpoint("0.0.0.0:8081")->host == "0.0.0.0");
  CHECK(view::parseEndpoint("[::1]:8082")->host == "::1");
  CHECK(view::parseEndpoint("localhost:8083")->host == "127.0.0.1");
  for (const char* bad : {"examples/grand_prix.lua", "99999", "-1", "8080x", "example.com:80",
                          "1.2.3.4:", "[::1]", ":", "1e3", "18446744073709551617"}) {
    auto r = view::parseEndpoint(bad);
    CHECK_MESSAGE(!r, bad);
    if (!r) CHECK(r.error().find(bad) != std::string::npos);
  }
}

TEST_CASE("view server: /ws sends the state, then at most the rate, and only what changed") {
  Rig rig(20);
  // something changes all the time: an event every 2 ms
  std::function<void()> tick = [&] {
    rig.feed.event("info", "tick");
    rig.loop.after(std::chrono::milliseconds(2), tick);
  };
  rig.loop.after(std::chrono::milliseconds(2), tick);
  int updates = 0;
  double first = -1, last = -1;
  rig.with([&](std::uint16_t port) {
    WsClient c(port);
    CHECK(c.read()["type"] == "state");
    auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
    while (std::chrono::steady_clock::now() < until) {
      auto u = c.read();
      CHECK(u["type"] == "update");
      CHECK(u["events"].size() > 0);
      if (first < 0) first = u["time"];
      last = u["time"];
      ++updates;
    }
  });
  // 20 a second at most: over the engine time they span, never more (and they did flow)
  CHECK(updates >= 10);
  CHECK(updates - 1 <= (last - first) * 20 + 1);
}

TEST_CASE("view server: a browser that never reads costs the others nothing and is closed") {
  Rig rig(30);
  // a fat state: 200 events of 1000 characters, changing every 5 ms — a stalled socket fills
  std::function<void()> tick = [&] {
    rig.feed.event("info", std::string(1000, 'x'));
    rig.loop.after(std::chrono::milliseconds(5), tick);
  };
  rig.loop.after(std::chrono::milliseconds(5), tick);
  // the loop's own timers keep their time while the stalled browser is attached
  double worstLate = 0;
  std::function<void()> beat;
  auto due = rig.loop.now() + std::chrono::milliseconds(10);
  beat = [&] {
    worstLate = std::max(worstLate, toSeconds(rig.loop.now() - due));
    due = rig.loop.now() + std::chrono::milliseconds(10);
    rig.loop.after(std::chrono::milliseconds(10), beat);
  };
  rig.loop.after(std::chrono::milliseconds(10), beat);
  int healthy = 0;
  std::size_t clientsWhileStalled = 0;
  rig.with(
      [&](std::uint16_t port) {
        WsClient stalled(port);  // handshakes, then reads nothing, ever
        stalled.ws.next_layer().set_option(asio::socket_base::receive_buffer_size(4096));
        WsClient good(port);
        (void)good.read();
        auto until = std::chrono::steady_clock::now() + std::chrono::seconds(7);
        while (std::chrono::steady_clock::now() < until) {
          (void)good.read();
          ++healthy;
          if (healthy == 30) clientsWhileStalled = rig.server->clients();
        }
      },
      std::chrono::seconds(30));
  CHECK(healthy >= 100);  // ~30 a second for 7 s, the stalled one beside it
  CHECK(clientsWhileStalled == 2);
  // the stalled browser was closed after 5 s of not reading; the good one stays
  CHECK(runUntil(
      rig.loop, [&] { return rig.server->clients() <= 1; }, std::chrono::seconds(2)));
  CHECK(worstLate < 0.5);  // no write ever blocked the loop
}

TEST_CASE("view server: hostile messages from a page are refused and the others go on") {
  Rig rig(30);
  int controls = 0;
  std::string lastControl;
  rig.with([&](std::uint16_t port) {
    {
      WsClient c(port);
      (void)c.read();
      c.ws.text(true);
      // a control on a live run: answered with an error, never obeyed
      c.ws.write(asio::buffer(std::string(R"({"type":"control","pause":true})")));
      for (int i = 0; i < 50; ++i) {
        auto m = c.read();
        if (m["type"] == "error") {
          CHECK(m["message"].get<std::string>().find("replay") != std::string::npos);
          break;
        }
        CHECK(i < 49);
      }
      // junk, deep nesting, a flood: ignored
      c.ws.write(asio::buffer(std::string("not json")));
      c.ws.write(asio::buffer(std::string(30000, '[')));
      c.ws.write(asio::buffer(std::string(R"({"type":"control","seek":1e999})")));
      for (int i = 0; i < 2000; ++i) c.ws.write(asio::buffer(std::string(R"({"type":"hello"})")));
      CHECK(c.read()["type"] == "update");
    }
    {
      WsClient c(port);  // a message beyond 64 KiB: this browser is closed
      (void)c.read();
      c.ws.binary(true);
      beast::error_code ec;
      c.ws.write(asio::buffer(std::string(1 << 20, 'x')), ec);
      beast::flat_buffer b;
      for (int i = 0; i < 100 && !ec; ++i) c.ws.read(b, ec);
      CHECK(ec);
    }
    {
      WsClient c(port);  // invalid UTF-8 in a text frame: closed by the WebSocket rules
      (void)c.read();
      c.ws.text(true);
      beast::error_code ec;
      c.ws.write(asio::buffer(std::string("{\"type\":\"\xff\xfe\"}")), ec);
      beast::flat_buffer b;
      for (int i = 0; i < 100 && !ec; ++i) c.ws.read(b, ec);
      CHECK(ec);
    }
    WsClient after(port);  // and the server goes on
    CHECK(after.read()["type"] == "state");
  });
  // with a replay's handler, controls reach it
  rig.feed.onControl = [&](const nlohmann::json& m) {
    ++controls;
    lastControl = m.dump();
  };
  rig.with([&](std::uint16_t port) {
    WsClient c(port);
    (void)c.read();
    c.ws.text(true);
    c.ws.write(asio::buffer(std::string(R"({"type":"control","seek":12.5})")));
    (void)c.read();
    (void)c.read();
  });
  CHECK(controls == 1);
  CHECK(lastControl.find("12.5") != std::string::npos);
}

TEST_CASE("view server: a message whose type is no string, or a control that throws: no crash") {
  Rig rig(30);
  rig.feed.onControl = [](const nlohmann::json& m) {
    (void)m.at("seek").get<double>();  // throws for {"seek":"x"}: the server must not pass it on
  };
  rig.with([&](std::uint16_t port) {
    WsClient c(port);
    (void)c.read();
    c.ws.text(true);
    for (const char* m :
         {R"({"type":5})", R"({"type":null})", R"({"type":[]})", R"({"type":{"a":1}})",
          R"([{"type":"control"}])", R"("control")", R"({"type":"control","seek":"x"})"})
      c.ws.write(asio::buffer(std::string(m)));
    bool refused = false;
    for (int i = 0; i < 100 && !refused; ++i) {
      auto m = c.read();
      refused = m["type"] == "error" &&
                m["message"].get<std::string>().find("control refused") != std::string::npos;
    }
    CHECK(refused);
    WsClient again(port);  // the server (and the process) goes on
    CHECK(again.read()["type"] == "state");
  });
}

TEST_CASE("view server: another site's page may not connect; HEAD has no body; limits answered") {
  Rig rig;
  rig.with([&](std::uint16_t port) {
    auto upgrade = [&](const std::string& origin) {
      asio::io_context io;
      websocket::stream<tcp::socket> ws(io);
      ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
      ws.set_option(websocket::stream_base::decorator([&](websocket::request_type& req) {
        if (!origin.empty()) req.set(http::field::origin, origin);
      }));
      beast::error_code ec;
      ws.handshake("127.0.0.1:" + std::to_string(port), "/ws", ec);
      return !ec;
    };
    CHECK_FALSE(upgrade("https://evil.example"));
    CHECK_FALSE(upgrade("http://127.0.0.1:1"));
    CHECK(upgrade("http://127.0.0.1:" + std::to_string(port)));  // the view's own page
    CHECK(upgrade(""));                                          // a tool: no Origin

    {  // HEAD: the headers (with the length of the body a GET would get), and nothing after them
      asio::io_context io;
      tcp::socket s(io);
      s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
      asio::write(s,
                  asio::buffer(std::string(
                      "HEAD /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")));
      std::string all;
      beast::error_code ec;
      char buf[4096];
      for (std::size_t n; (n = s.read_some(asio::buffer(buf), ec)) > 0 || !ec;) all.append(buf, n);
      CHECK(all.starts_with("HTTP/1.1 200"));
      CHECK(all.find("Content-Length: ") != std::string::npos);
      CHECK(all.ends_with("\r\n\r\n"));
    }
    auto big = httpGet(port, "/", http::verb::get, std::string(20 * 1024, 'x'));
    CHECK(big.result() == http::status::request_header_fields_too_large);
  });
}

TEST_CASE("view server: at most 64 browsers; the next is told so, and the server goes on") {
  Rig rig;
  rig.with(
      [&](std::uint16_t port) {
        std::vector<std::unique_ptr<WsClient>> clients;
        for (int i = 0; i < 64; ++i) clients.push_back(std::make_unique<WsClient>(port));
        bool refused = false;
        try {
          WsClient one(port);
        } catch (const std::exception& e) {
          refused = true;
        }
        CHECK(refused);
        clients.pop_back();
        // one closed: room again (the server notices the close first)
        bool connected = false;
        for (int attempt = 0; attempt < 50 && !connected; ++attempt) {
          try {
            WsClient one(port);
            connected = one.read()["type"] == "state";
          } catch (const std::exception&) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          }
        }
        CHECK(connected);
      },
      std::chrono::seconds(60));
}

TEST_CASE("view server: stop() closes every browser (the page says the engine is gone)") {
  Rig rig;
  bool closed = false;
  std::atomic<bool> connected{false};
  std::thread t([&] {
    WsClient c(rig.server->port());
    (void)c.read();
    connected = true;
    beast::error_code ec;
    beast::flat_buffer b;
    while (!ec) c.ws.read(b, ec);
    closed = true;
  });
  REQUIRE(runUntil(rig.loop, [&] { return connected.load(); }));
  rig.server->stop();
  runUntil(
      rig.loop, [&] { return false; }, std::chrono::milliseconds(200));
  t.join();
  CHECK(closed);
}

TEST_CASE(
    "view server: the page's folder is $PITWALL_VIEW_DIR first; one without a page is passed") {
  Assets assets;
  setenv("PITWALL_VIEW_DIR", assets.dir.c_str(), 1);
  auto found = view::findAssets();
  REQUIRE(found);
  CHECK(*found == std::filesystem::weakly_canonical(assets.dir));
  // a folder without index.html is not taken: the next place is (the build tree's page)
  setenv("PITWALL_VIEW_DIR", (assets.dir / "vendor").c_str(), 1);
  auto next = view::findAssets();
  if (next)
    CHECK(*next != std::filesystem::weakly_canonical(assets.dir / "vendor"));
  else
    CHECK(next.error().find("PITWALL_VIEW_DIR") != std::string::npos);
  unsetenv("PITWALL_VIEW_DIR");
}

// DNS rebinding (issue 33): a page of attacker.example whose name was made to resolve to this
// machine sends its own name as Host and as Origin — they match each other, so only the Host
// check tells it from the view's own page.
TEST_CASE("view server: a page whose name was rebound here is refused on /ws and on the page") {
  Rig rig;
  rig.with([&](std::uint16_t port) {
    const std::string p = ":" + std::to_string(port);
    auto handshake = [&](const std::string& host, const std::string& origin) {
      try {
        WsClient c(port, "127.0.0.1", "/ws", host, origin);
        return c.read()["type"] == "state";
      } catch (const std::exception&) {
        return false;
      }
    };
    CHECK_FALSE(handshake("attacker.example" + p, "http://attacker.example" + p));
    CHECK_FALSE(handshake("attacker.example", ""));  // a tool without Origin: the Host still
    auto page = httpGet(port, "/", http::verb::get, "", "attacker.example" + p);
    CHECK(page.result() == http::status::forbidden);
    CHECK(page.body().find("does not serve the name 'attacker.example" + p) != std::string::npos);
    CHECK(page.body().find("--view-host") != std::string::npos);
    CHECK(httpGet(port, "/api/state", http::verb::get, "", "attacker.example").result() ==
          http::status::forbidden);
    // the names it serves: loopback by address and by name, this machine's name
    CHECK(handshake("127.0.0.1" + p, "http://127.0.0.1" + p));
    CHECK(handshake("127.0.0.7" + p, "http://127.0.0.7" + p));
    CHECK(handshake("[::1]" + p, "http://[::1]" + p));
    CHECK(handshake("localhost" + p, "http://localhost" + p));
    CHECK(handshake("LocalHost." + p, ""));
    char name[256] = {};
    REQUIRE(::gethostname(name, sizeof name - 1) == 0);
    CHECK(handshake(std::string(name) + p, "http://" + std::string(name) + p));
    CHECK(httpGet(port, "/", http::verb::get, "", "localhost" + p).result() == http::status::ok);
    // a served Host with another site's Origin, a malformed Host
    CHECK_FALSE(handshake("127.0.0.1" + p, "http://attacker.example" + p));
    CHECK(httpGet(port, "/", http::verb::get, "", "127.0.0.1:1:2").result() ==
          http::status::forbidden);
  });
}

TEST_CASE("view server: --view-host adds a reverse proxy's name, and only that") {
  Assets assets;
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  view::Feed feed{loop, fleet, "simulator"};
  view::ServerOptions o;
  o.assets = assets.dir;
  o.names = {"Race.Example.org"};
  view::Server server(loop, feed, o);
  REQUIRE(server.start());
  CHECK(server.joinCode().size() == 6);  // behind a proxy, phones come from anywhere
  runClient(loop, server.port(), [&](std::uint16_t port) {
    CHECK(httpGet(port, "/", http::verb::get, "", "race.example.org").result() == http::status::ok);
    WsClient proxied(port, "127.0.0.1", "/ws", "race.example.org", "https://race.example.org");
    CHECK(proxied.read()["type"] == "state");
    CHECK(httpGet(port, "/", http::verb::get, "", "other.example.org").result() ==
          http::status::forbidden);
  });
}
