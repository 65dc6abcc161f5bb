#pragma once
// The race view's HTTP + WebSocket server (docs/view.md), on the engine's one loop (Boost.Beast):
//   GET /            the page, and its assets, from the installed data folder
//   GET /drive       the controller page (drive.html): a phone takes a seat and drives it
//   GET /api/state   the feed's whole state as JSON
//   GET /code        with a classroom (--code): the code page, and its requests /api/code/…
//                    (engine/view/code_api.hpp)
// Every request's Host must be a name the view serves (loopback, this machine's addresses and
// name, the bound address, --view-host) and its Origin, when sent, that Host: a page on another
// site, even one whose name was made to resolve here (DNS rebinding), is refused (403).
//   GET /ws          a WebSocket: the state, then updates at most `maxRate` a second; a page
//                    may send replay controls and, with the feed's seats, seat/drive/leave
//                    (each WebSocket is one holder; closing it frees its seat)
// A browser that reads slowly gets fewer updates, never a queue: each connection has at most one
// write in flight and the next update is built when it is done. A closed or stalled browser
// costs the loop nothing (writes are asynchronous; a write that stalls past a limit closes it).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/view/assets.hpp"
#include "engine/view/feed.hpp"

namespace pitwall::classroom {
class Classroom;
}

namespace pitwall::view {

struct ServerOptions {
  std::string host = "127.0.0.1";  // another address only when given (--view HOST:PORT)
  std::uint16_t port = 0;          // 0: any free port
  std::filesystem::path assets;    // the page's folder (index.html, view.js, vendor/…)
  double maxRate = 30;             // updates a second per browser, at most
  // --view-host: more names a browser may reach the view by (a reverse proxy's). Requests whose
  // Host is one of them, from this machine, are taken as forwarded: X-Forwarded-For names the
  // client. Any name here makes the join code needed.
  std::vector<std::string> names;
  bool alwaysPair = false;  // the join code is needed on loopback too (tests)
  std::string code;         // the join code when one is needed; empty: a new one (getrandom)
  // --code: the classroom the code page serves (GET /code, /api/code/…; docs/classroom.md);
  // nullptr: the page is off. `tests` children run at once (Test: `pitwall try`).
  classroom::Classroom* classroom = nullptr;
  int tests = 2;
};

// "[HOST:]PORT" from the command line; an empty text is the default port. The error says what
// was wrong and what to write.
inline constexpr std::uint16_t kDefaultPort = 8080;
Result<ServerOptions, std::string> parseEndpoint(const std::string& text);

class Server {
 public:
  Server(Loop& loop, Feed& feed, ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens; the error names the address and what to do (a port in use, say).
  Result<bool, std::string> start();
  void stop();  // closes every connection; the pages show "engine gone"
  std::uint16_t port() const;
  std::string url() const;
  std::size_t clients() const;  // open WebSockets
  // The code that pairs a phone (docs/view.md "Pairing"); empty when none is needed (loopback,
  // no --view-host). driveUrl(): the controller page's address, with the code; viewUrl(): the
  // race view's (its replay controls), with the code. Both by an address a phone can reach.
  std::string joinCode() const;
  std::string driveUrl() const;
  std::string viewUrl() const;
  // The code page (with --code), with the join code; the teacher's page, with the teacher's key.
  std::string codeUrl() const;
  std::string teacherUrl() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace pitwall::view
