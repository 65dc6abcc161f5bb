// The controller page's messages on the race view's WebSocket (docs/view.md "The controller page"):
// a page takes a seat, drives it, leaves it; a second page cannot take a held seat; a page that
// closes or goes silent has its car slowed to a stop; hostile messages are answered or dropped,
// never thrown out of the loop. Real loopback sockets and a real clock, as server_test.cpp; the
// cars are simulated ones behind the real codec, so "speed 0" is the command the car was sent.
#include <doctest/doctest.h>

#include <functional>

#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <filesystem>
#include <fstream>

#include "engine/drive/seats.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/track.hpp"
#include "engine/sim/world.hpp"
#include "engine/view/pairing.hpp"
#include "engine/view/server.hpp"
#include "tests/support/run_until.hpp"
#include "tests/support/sim_cars.hpp"
#include "tests/unit/view/server_client.hpp"

using namespace pitwall;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using testing::httpGet;
using testing::runClient;
using testing::runUntil;
using testing::WsClient;

namespace {

struct Rig {
  std::filesystem::path assets;
  Loop loop{ClockKind::Real};
  sim::World world{loop, sim::namedLayout("oval").value(), 1};
  Fleet fleet{loop};
  std::unique_ptr<drive::Seats> seats;
  view::Feed feed{loop, fleet, "simulator"};
  std::unique_ptr<view::Server> server;

  explicit Rig(int humans, int cars = 2, drive::SeatsOptions seatOptions = {},
               const std::function<void(view::ServerOptions&)>& configure = {}) {
    assets = std::filesystem::temp_directory_path() /
             ("pitwall-drive-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(assets);
    std::ofstream(assets / "index.html") << "<!doctype html><title>race view</title>";
    std::ofstream(assets / "drive.html") << "<!doctype html><title>drive</title>";
    for (int i = 0; i < cars; ++i)
      testing::addSimulatedCar(loop, fleet, world,
                               sim::CarSpec{.name = "car" + std::to_string(i + 1),
                                            .piece_index = 0,
                                            .offset_mm = i % 2 ? 68.0 : -68.0});
    REQUIRE(runUntil(loop, [&] {
      for (AnkiCar* c : fleet.cars())
        if (!c->state().connected) return false;
      return true;
    }));
    for (AnkiCar* c : fleet.cars()) REQUIRE(c->sdkMode(true));
    if (humans > 0) {
      seats = std::make_unique<drive::Seats>(loop, fleet, humans, seatOptions);
      feed.setSeats(seats.get());
    }
    view::ServerOptions o;
    o.port = 0;
    o.assets = assets;
    if (configure) configure(o);
    server = std::make_unique<view::Server>(loop, feed, o);
    REQUIRE(server->start());
  }
  ~Rig() {
    server.reset();
    feed.setSeats(nullptr);
    std::filesystem::remove_all(assets);
  }
  // Runs `client` in a thread while the loop runs, as server_test.cpp does.
  void with(const std::function<void(std::uint16_t port)>& client,
            Duration limit = std::chrono::seconds(20)) {
    runClient(loop, server->port(), client, limit);
  }
  // Runs the loop for `seconds` (the seats' timers, the cars' frames).
  void pass(double seconds) {
    runUntil(
        loop, [] { return false; }, fromSeconds(seconds));
  }
  AnkiCar& car(int number) { return *fleet.find(number); }
};

// A phone: sends messages, reads until an answer (a "seat" or an "error"), skipping updates.
struct Phone : WsClient {
  using WsClient::WsClient;
  nlohmann::json answer() {
    for (;;) {
      auto m = read();
      if (m["type"] == "seat" || m["type"] == "error") return m;
    }
  }
  // The next update (or state) whose seats satisfy `ok`.
  nlohmann::json seatsWhere(const std::function<bool(const nlohmann::json&)>& ok) {
    for (;;) {
      auto m = read();
      if ((m["type"] == "update" || m["type"] == "state") && m.contains("seats") && ok(m["seats"]))
        return m["seats"];
    }
  }
  void close() {
    beast::error_code ignored;
    ws.close(websocket::close_code::normal, ignored);
  }
};

nlohmann::json seatMessage(int seat, const std::string& player) {
  return {{"type", "seat"}, {"seat", seat}, {"player", player}};
}
nlohmann::json driveMessage(double throttle, int lane = 0) {
  return {{"type", "drive"}, {"throttle", throttle}, {"lane", lane}};
}
// A phone on `port` that has taken seat `seat` as `player`.
std::unique_ptr<Phone> seatedPhone(std::uint16_t port, int seat, const std::string& player) {
  auto phone = std::make_unique<Phone>(port);
  phone->send(seatMessage(seat, player));
  CHECK(phone->answer()["seat"] == seat);
  return phone;
}

}  // namespace

TEST_CASE("view drive: a page takes a free seat; a second page cannot take it, takes another") {
  Rig rig(2);
  std::unique_ptr<Phone> a, b;
  rig.with([&](std::uint16_t port) {
    a = std::make_unique<Phone>(port);
    b = std::make_unique<Phone>(port);
    auto state = a->read();
    REQUIRE(state["type"] == "state");
    REQUIRE(state["seats"].size() == 2);
    CHECK(state["seats"][0]["number"] == 1);
    CHECK(state["seats"][0]["car"] == "car1");
    CHECK(state["seats"][0]["held"] == false);
    CHECK(state["seats"][0]["holder"].is_null());

    a->send(seatMessage(1, "Anna"));
    CHECK(a->answer() == nlohmann::json{{"type", "seat"}, {"seat", 1}});
    b->send(seatMessage(1, "Ben"));
    auto refused = b->answer();
    CHECK(refused["type"] == "error");
    CHECK(refused["message"].get<std::string>().find("seat 1 is held") != std::string::npos);
    CHECK(refused["message"].get<std::string>().find("Anna") != std::string::npos);
    b->send(seatMessage(0, "Ben"));  // any free one
    CHECK(b->answer() == nlohmann::json{{"type", "seat"}, {"seat", 2}});

    // every page sees who holds what (not the holder's connection id)
    auto seats = b->seatsWhere([](const nlohmann::json& s) { return s[1]["held"] == true; });
    CHECK(seats[0]["player"] == "Anna");
    CHECK(seats[0]["holder"] == "phone");
    CHECK(seats[0]["live"] == true);
    CHECK(seats[1]["player"] == "Ben");
  });
  REQUIRE(rig.seats->seat(1)->held());
  CHECK(rig.seats->seat(1)->holder != rig.seats->seat(2)->holder);
  CHECK(rig.seats->seat(1)->kind == drive::Holder::Phone);
  auto state = rig.feed.state();
  CHECK(state["seats"][0]["held"] == true);
}

TEST_CASE("view drive: a page drives its own seat only, and leaving stops the car") {
  Rig rig(2, 2, {.silence = 10});  // no silence in this test: it is another
  std::unique_ptr<Phone> a, b;
  rig.with([&](std::uint16_t port) {
    a = seatedPhone(port, 1, "Anna");
    b = std::make_unique<Phone>(port);
    a->send(driveMessage(0.5, 1));
    b->send(driveMessage(1.0));  // b holds no seat
    auto refused = b->answer();
    CHECK(refused["type"] == "error");
    CHECK(refused["message"].get<std::string>().find("take one first") != std::string::npos);
    // the throttle reaches every page with the next update
    a->seatsWhere([](const nlohmann::json& s) { return s[0]["throttle"] == 0.5; });
  });
  CHECK(rig.seats->seat(1)->throttle == 0.5);
  CHECK(rig.seats->takeLanes(1) == 1);
  CHECK(rig.seats->seat(2)->throttle == 0);
  // the human driver (the race library) would command the car from the seat; here the test does
  REQUIRE(rig.car(1).setSpeed(600, 2000));
  rig.seats->driving(1);
  rig.with([&](std::uint16_t) {
    a->send(R"({"type":"leave"})");
    a->seatsWhere([](const nlohmann::json& s) { return s[0]["held"] == false; });
  });
  CHECK_FALSE(rig.seats->seat(1)->held());
  CHECK(rig.car(1).state().target_speed_mm_s == 0);
}

TEST_CASE("view drive: a page that closes frees its seat and its car is commanded to stop") {
  Rig rig(2, 2, {.silence = 10});
  std::unique_ptr<Phone> a, b;
  rig.with([&](std::uint16_t port) {
    a = seatedPhone(port, 1, "Anna");
    b = seatedPhone(port, 2, "Ben");
  });
  REQUIRE(rig.car(1).setSpeed(700, 2000));
  REQUIRE(rig.car(2).setSpeed(700, 2000));
  rig.seats->driving(1);  // (as the human driver says at every update)
  rig.seats->driving(2);
  SUBCASE("closed by the page") {
    rig.with([&](std::uint16_t) { a->close(); });
  }
  SUBCASE("the connection dropped without a close") {
    rig.with([&](std::uint16_t) {
      beast::error_code ignored;
      a->ws.next_layer().close(ignored);
    });
  }
  REQUIRE(runUntil(rig.loop, [&] { return !rig.seats->seat(1)->held(); }));
  CHECK(rig.car(1).state().target_speed_mm_s == 0);
  CHECK(rig.car(2).state().target_speed_mm_s == 700);  // the other seat is untouched
  CHECK(rig.seats->seat(2)->held());
  // seat 1 is free again for another phone
  rig.with([&](std::uint16_t port) {
    auto c = seatedPhone(port, 1, "Cleo");
    b->close();
  });
}

TEST_CASE("view drive: a page silent for 1 s loses its input: the car is commanded to stop") {
  Rig rig(1);
  std::unique_ptr<Phone> a;
  rig.with([&](std::uint16_t port) {
    a = seatedPhone(port, 1, "Anna");
    a->send(driveMessage(0.8));
  });
  REQUIRE(runUntil(rig.loop, [&] { return rig.seats->seat(1)->throttle == 0.8; }));
  REQUIRE(rig.car(1).setSpeed(800, 2000));
  // a driver drives from the seat, saying so every 0.1 s (as the human driver does)
  bool driven = true;
  std::function<void()> drive = [&] {
    if (!driven) return;
    rig.seats->driving(1);
    rig.loop.after(fromSeconds(0.1), drive);
  };
  drive();
  const double from = rig.loop.seconds();
  REQUIRE(runUntil(
      rig.loop, [&] { return !rig.seats->seat(1)->live; }, std::chrono::seconds(3)));
  CHECK(rig.loop.seconds() - from <= 1.2);
  CHECK(rig.seats->seat(1)->held());  // still held: the next input makes it live again
  CHECK(rig.seats->seat(1)->throttle == 0);
  CHECK(rig.car(1).state().target_speed_mm_s == 0);
  rig.with([&](std::uint16_t) {
    a->send(driveMessage(0.3));
    a->seatsWhere([](const nlohmann::json& s) { return s[0]["live"] == true; });
  });
  CHECK(rig.seats->seat(1)->throttle == 0.3);
  driven = false;
}

TEST_CASE("view drive: hostile messages are refused or dropped, never thrown") {
  Rig rig(2);
  std::unique_ptr<Phone> kept;
  rig.with([&](std::uint16_t port) {
    // (each page has its own allowance of messages: the groups below are within one)
    kept = std::make_unique<Phone>(port);
    Phone& a = *kept;
    for (const char* bad :
         {R"({"type":"seat","seat":3})", R"({"type":"seat","seat":-1})",
          R"({"type":"seat","seat":1.5})", R"({"type":"seat","seat":"1"})",
          R"({"type":"seat","seat":1e300})", R"({"type":"seat","seat":null})",
          R"({"type":"seat","seat":18446744073709551617})", R"({"type":"seat","seat":[1]})",
          R"({"type":"seat","seat":1,"player":42})", R"({"type":"seat","seat":1,"player":{}})"}) {
      a.send(std::string(bad));
      auto m = a.answer();
      CHECK_MESSAGE(m["type"] == "error", bad);
      CHECK_MESSAGE(!m["message"].get<std::string>().empty(), bad);
    }
    // a seat nested 30 000 arrays deep, in the 64 KB a message may have: named by its type (a
    // recursive dump of it would overflow the stack)
    a.send(R"({"type":"seat","seat":)" + std::string(30000, '[') + std::string(30000, ']') + "}");
    {
      auto m = a.answer();
      CHECK(m["type"] == "error");
      CHECK(m["message"].get<std::string>().find("seat (array) is not a seat") !=
            std::string::npos);
    }
    // a name with control characters and a long one: taken, kept short and printable (below)
    a.send(R"({"type":"seat","seat":1,"player":"\u0000\u001b[31mAnna)" + std::string(300, 'x') +
           "\"}");
    CHECK(a.answer()["seat"] == 1);
    // not JSON, not an object, no type, unknown types, a type that is not text: ignored
    for (const char* ignored : {"", "{", "[]", "42", R"({"seat":1})", R"({"type":"hello"})",
                                R"({"type":7})", R"({"type":null})", "\"drive\""})
      a.send(std::string(ignored));

    Phone b(port);
    b.send(seatMessage(2, "Ben"));
    CHECK(b.answer()["seat"] == 2);
    // drive messages that are no drive: each refusal said (the same one once a second)
    for (const char* bad :
         {R"({"type":"drive","throttle":"NaN"})", R"({"type":"drive","throttle":1e308,"lane":0})",
          R"({"type":"drive","throttle":-0.5})", R"({"type":"drive","throttle":0.5,"lane":2})"}) {
      b.send(std::string(bad));
      auto m = b.answer();
      CHECK_MESSAGE(m["type"] == "error", bad);
    }
    // the same refusals again at once: not said again (no reply flood), and nothing taken
    for (const char* again : {R"({"type":"drive","throttle":"1"})", R"({"type":"drive"})",
                              R"({"type":"drive","throttle":0.5,"lane":0.5})",
                              R"({"type":"drive","throttle":0.5,"lane":"left"})"})
      b.send(std::string(again));
    // a flood: dropped, said once, and the seat is not lost over it
    for (int i = 0; i < 500; ++i) b.send(driveMessage(0.25));
    auto flood = b.answer();
    CHECK(flood["type"] == "error");
    CHECK_MESSAGE(
        flood["message"].get<std::string>().find("too many messages") != std::string::npos,
        flood.dump());
    b.send(R"({"type":"leave"})");  // taken even in a flood
    b.seatsWhere([](const nlohmann::json& s) { return s[1]["held"] == false; });
  });
  CHECK_FALSE(rig.seats->seat(2)->held());
  REQUIRE(rig.seats->seat(1)->held());
  const std::string& player = rig.seats->seat(1)->player;
  CHECK(player.find('\0') == std::string::npos);
  CHECK(player.find('\x1b') == std::string::npos);
  CHECK(player.size() <= 24 + 3);  // 24 bytes, then "…"
}

TEST_CASE("view drive: a player's name is kept printable") {
  Rig rig(1);
  std::unique_ptr<Phone> a;
  rig.with([&](std::uint16_t port) {
    a = std::make_unique<Phone>(port);
    a->send(R"({"type":"seat","seat":0,"player":"\u0007Zo\u00e9)" + std::string(100, 'y') + "\"}");
    CHECK(a->answer()["seat"] == 1);
  });
  const std::string& player = rig.seats->seat(1)->player;
  CHECK(player.find('\x07') == std::string::npos);
  CHECK(player.size() <= 24 + 3);  // 24 bytes, then "…"
  CHECK_MESSAGE(player.find("Zo\xc3\xa9") != std::string::npos, player);
}

TEST_CASE("view drive: without seats, driving is off and says how to start it") {
  Rig rig(0);
  rig.with([&](std::uint16_t port) {
    Phone a(port);
    CHECK(a.read()["seats"] == nlohmann::json::array());
    for (auto m : {seatMessage(1, "Anna"), driveMessage(0.5)}) {
      a.send(m);
      auto r = a.answer();
      CHECK(r["type"] == "error");
      CHECK(r["message"].get<std::string>().find("--humans N") != std::string::npos);
    }
    a.send(R"({"type":"leave"})");  // nothing to let go of: no answer, no harm
    a.send(R"({"type":"control","pause":true})");
    CHECK(a.answer()["message"].get<std::string>().find("replays") != std::string::npos);
  });
}

TEST_CASE("view drive: GET /drive serves the controller page") {
  Rig rig(1);
  rig.with([&](std::uint16_t port) {
    auto res = httpGet(port, "/drive");
    CHECK(res.result() == beast::http::status::ok);
    CHECK(res.body().find("<title>drive</title>") != std::string::npos);
    CHECK(std::string(res[beast::http::field::content_type]).starts_with("text/html"));
  });
}

// Pairing (docs/view.md "Pairing"): off loopback — here forced with alwaysPair, as the view on
// 0.0.0.0 would be — a seat is taken only with the join code, and a code cannot be guessed.
namespace {
constexpr const char* kCode = "424242";
void needCode(view::ServerOptions& o) {
  o.alwaysPair = true;
  o.code = kCode;
}
nlohmann::json withCode(nlohmann::json m, const std::string& code) {
  m["code"] = code;
  return m;
}
bool says(const nlohmann::json& answer, const std::string& part) {
  return answer["type"] == "error" &&
         answer["message"].get<std::string>().find(part) != std::string::npos;
}
}  // namespace

TEST_CASE("view drive: off loopback a page without the join code cannot take a seat or drive") {
  Rig rig(2, 2, {}, needCode);
  CHECK(rig.server->joinCode() == kCode);
  CHECK(rig.server->driveUrl().ends_with("/drive?code=424242"));
  rig.with([&](std::uint16_t port) {
    Phone spectator(port, "127.0.0.2", "/ws");
    spectator.send(seatMessage(1, "Eve"));
    auto refused = spectator.answer();
    CHECK_MESSAGE(says(refused, "needs its join code"), refused.dump());
    spectator.send(driveMessage(1.0));
    CHECK(says(spectator.answer(), "needs its join code"));
    spectator.send(R"({"type":"control","pause":true})");
    CHECK(says(spectator.answer(), "needs its join code"));
    // still read-only: the seats it sees are free
    spectator.seatsWhere([](const nlohmann::json& s) { return s[0]["held"] == false; });

    // the code in the page's address (/ws?code=…), or in its seat message
    Phone invited(port, "127.0.0.3", std::string("/ws?code=") + kCode);
    invited.send(seatMessage(1, "Anna"));
    CHECK(invited.answer()["seat"] == 1);
    Phone typed(port, "127.0.0.4", "/ws");
    typed.send(withCode(seatMessage(2, "Ben"), kCode));
    CHECK(typed.answer()["seat"] == 2);
    // what every page sees: both seats held (by the paired phones)
    spectator.seatsWhere(
        [](const nlohmann::json& s) { return s[0]["held"] == true && s[1]["held"] == true; });
  });
}

TEST_CASE("view drive: wrong join codes lock their address out; another address still pairs") {
  Rig rig(1, 1, {}, needCode);
  rig.with([&](std::uint16_t port) {
    Phone guesser(port, "127.0.0.5", "/ws");
    for (int i = 1; i <= view::Pairing::kFreeTries; ++i) {
      guesser.send(withCode(seatMessage(1, "Eve"), std::to_string(100000 + i)));
      auto m = guesser.answer();
      CHECK_MESSAGE(says(m, "wrong join code"), m.dump());
      if (i == view::Pairing::kFreeTries) CHECK_MESSAGE(says(m, "no more tries from"), m.dump());
    }
    // locked out: the right code is refused too, and so is a new page from the same address
    guesser.send(withCode(seatMessage(1, "Eve"), kCode));
    auto locked = guesser.answer();
    CHECK_MESSAGE(says(locked, "too many wrong join codes from 127.0.0.5: try again in"),
                  locked.dump());
    Phone again(port, "127.0.0.5", std::string("/ws?code=") + kCode);
    again.send(seatMessage(1, "Eve"));
    CHECK(says(again.answer(), "too many wrong join codes"));
    // a phone elsewhere is not held back by the guesser
    Phone phone(port, "127.0.0.6", std::string("/ws?code=") + kCode);
    phone.send(seatMessage(1, "Anna"));
    CHECK(phone.answer()["seat"] == 1);
  });
}

TEST_CASE("view drive: the race view on the engine's machine is told the join code") {
  Rig rig(1, 1, {}, needCode);
  rig.with([&](std::uint16_t port) {
    WsClient view(port);
    for (;;) {
      auto m = view.read();
      if (m["type"] != "pairing") continue;
      CHECK(m["code"] == kCode);
      CHECK(m["drive"].get<std::string>().ends_with("/drive?code=424242"));
      break;
    }
  });
}

TEST_CASE("view drive: on loopback no join code is needed (and none is shown)") {
  Rig rig(1, 1);
  CHECK(rig.server->joinCode().empty());
  CHECK(rig.server->driveUrl().ends_with("/drive"));
  rig.with([&](std::uint16_t port) { seatedPhone(port, 1, "Anna"); });
}

TEST_CASE("view drive: replay controls need the join code off loopback") {
  Rig rig(0, 1, {}, needCode);
  int controls = 0;
  rig.feed.onControl = [&](const nlohmann::json&) { ++controls; };
  rig.with([&](std::uint16_t port) {
    Phone viewer(port, "127.0.0.2", "/ws");
    viewer.send(R"({"type":"control","pause":true})");
    CHECK(says(viewer.answer(), "needs its join code"));
    Phone owner(port, "127.0.0.3", std::string("/ws?code=") + kCode);
    owner.send(R"({"type":"control","pause":true})");
    owner.send(seatMessage(1, "x"));  // an answer after the control: the control was taken
    CHECK(says(owner.answer(), "--humans N"));
  });
  CHECK(controls == 1);
}

// Fairness (issue 33): squatters on several addresses — TCP connections that send nothing,
// requests that never end (slowloris), kept-alive connections left idle, WebSockets that never
// read (so never answer a ping) — fill every slot; a phone with the code still gets its seat.
TEST_CASE("view drive: 200 idle and slow connections from 10 addresses do not keep a phone out") {
  Rig rig(1, 1, {}, needCode);
  namespace asio = boost::asio;
  rig.with(
      [&](std::uint16_t port) {
        asio::io_context io;
        std::vector<std::unique_ptr<asio::ip::tcp::socket>> idle;
        std::vector<std::unique_ptr<WsClient>> silent;
        for (int i = 0; i < 200; ++i) {
          const std::string from = "127.0.0." + std::to_string(2 + i % 10);
          const int kind = i % 20;
          try {
            if (kind >= 9 && kind < 16) {  // a WebSocket that never reads
              silent.push_back(std::make_unique<WsClient>(port, from, "/ws"));
              continue;
            }
            auto s = std::make_unique<asio::ip::tcp::socket>(io);
            WsClient::connectFrom(*s, from, port);
            if (kind >= 5 && kind < 9)  // slowloris: a header that never ends
              asio::write(*s, asio::buffer(std::string("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")));
            else if (kind >= 16)  // a kept-alive connection, left idle after one request
              asio::write(
                  *s,
                  asio::buffer(std::string("GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")));
            idle.push_back(std::move(s));
          } catch (const std::exception&) {
            // a squatter refused or pushed out by another squatter: the point of the test
          }
        }
        CHECK(silent.size() + idle.size() >= 150);
        const auto start = std::chrono::steady_clock::now();
        Phone phone(port, "127.0.0.1", std::string("/ws?code=") + kCode);
        phone.send(seatMessage(1, "Anna"));
        auto m = phone.answer();
        const auto took = std::chrono::steady_clock::now() - start;
        CHECK_MESSAGE(m["seat"] == 1, m.dump());
        CHECK_MESSAGE(took < std::chrono::seconds(2),
                      "the phone took " << std::chrono::duration<double>(took).count()
                                        << " s to get its seat");
      },
      std::chrono::seconds(60));
}

// The other squatting: every WebSocket slot held by a different address, one each (64 aliases
// of a LAN attacker). A page without the code is turned away; a phone with it takes the oldest
// unpaired page's slot and its seat.
TEST_CASE("view drive: 64 spectators from 64 addresses do not keep a phone with the code out") {
  Rig rig(1, 1, {}, needCode);
  rig.with(
      [&](std::uint16_t port) {
        std::vector<std::unique_ptr<WsClient>> spectators;
        for (int i = 0; i < 64; ++i)
          spectators.push_back(
              std::make_unique<WsClient>(port, "127.0.1." + std::to_string(i + 1), "/ws"));
        // one more without the code: no room, and nobody is pushed out for it
        CHECK_THROWS(WsClient(port, "127.0.2.1", "/ws"));
        Phone phone(port, "127.0.0.1", std::string("/ws?code=") + kCode);
        phone.send(seatMessage(1, "Anna"));
        auto m = phone.answer();
        CHECK_MESSAGE(m["seat"] == 1, m.dump());
      },
      std::chrono::seconds(60));
}

// Behind --view-host, every phone comes from the proxy's address: the proxy's X-Forwarded-For
// tells them apart — and only then (a client that names itself elsewhere is not believed).
TEST_CASE("view drive: behind --view-host, wrong codes are counted per forwarded client") {
  Rig rig(1, 1, {}, [](view::ServerOptions& o) {
    o.names = {"race.example.org"};
    o.code = kCode;
  });
  rig.with([&](std::uint16_t port) {
    auto guess = [&](const std::string& host, const std::string& xff, const std::string& code) {
      Phone p(port, "127.0.0.1", "/ws", host, "", xff);
      p.send(withCode(seatMessage(1, "Eve"), code));
      return p.answer();
    };
    for (int i = 0; i < view::Pairing::kFreeTries; ++i)
      guess("race.example.org", "10.9.9.9, 203.0.113.7", "000000");
    auto locked = guess("race.example.org", "203.0.113.7", kCode);
    CHECK_MESSAGE(says(locked, "too many wrong join codes from 203.0.113.7"), locked.dump());
    // another phone through the same proxy is not held back
    auto other = guess("race.example.org", "203.0.113.8", kCode);
    CHECK_MESSAGE(other["seat"] == 1, other.dump());
  });
  rig.with([&](std::uint16_t port) {
    // not through the proxy's name: X-Forwarded-For is the client's own word, not taken
    for (int i = 0; i < view::Pairing::kFreeTries; ++i) {
      Phone p(port, "127.0.0.9", "/ws", "127.0.0.1", "", "198.51.100." + std::to_string(i));
      p.send(withCode(seatMessage(1, "Eve"), "000000"));
      (void)p.answer();
    }
    Phone p(port, "127.0.0.9", "/ws", "127.0.0.1", "", "198.51.100.99");
    p.send(withCode(seatMessage(1, "Eve"), kCode));
    auto locked = p.answer();
    CHECK_MESSAGE(says(locked, "too many wrong join codes from 127.0.0.9"), locked.dump());
  });
}
