#include "engine/view/server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <charconv>
#include <fstream>
#include <list>
#include <map>
#include <set>
#include <sstream>

#include "engine/classroom/classroom.hpp"
#include "engine/core/child_runs.hpp"
#include "engine/core/log.hpp"
#include "engine/drive/seats.hpp"
#include "engine/view/assets.hpp"
#include "engine/view/code_api.hpp"
#include "engine/view/host_check.hpp"
#include "engine/view/lap_compare.hpp"
#include "engine/view/page_messages.hpp"

namespace pitwall::view {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

namespace {

constexpr auto kWriteStall = std::chrono::seconds(5);  // a browser that reads nothing for this long
constexpr auto kHeartbeat = std::chrono::seconds(1);   // an unchanged state is sent this often
constexpr std::size_t kMaxIncoming = 64 * 1024;        // a page's message, a request's body
// the code page's save or test: a driver file of 32 KiB at most, escaped in JSON
constexpr std::size_t kMaxCodeBody = 256 * 1024;
constexpr auto kRequestTimeout = std::chrono::seconds(5);  // for a request to arrive whole
constexpr auto kSocketIdle = std::chrono::seconds(10);  // a WebSocket that answers no ping: closed
constexpr std::size_t kMaxBrowsers = 64;                // WebSockets at once
constexpr std::size_t kMaxConnections = 128;            // HTTP connections at once (not upgraded)

std::string_view sv(beast::string_view v) {
  return {v.data(), v.size()};
}

constexpr auto kAcceptRetry = std::chrono::milliseconds(250);  // after a failed accept()

}  // namespace

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
  Impl(Loop& l, Feed& f, ServerOptions o)
      : loop(l),
        feed(f),
        options(std::move(o)),
        acceptor(l.io()),
        retry(l.io()),
        pairing(needsCode(options), options.code) {
    if (options.classroom) {
      ChildLimits limits;
      limits.parallel = std::max(1, options.tests);
      tests = std::make_unique<ChildRuns>(l, limits);
      // the teacher's league: one at a time, a few minutes at most (every pair of drivers meets)
      leagues = std::make_unique<ChildRuns>(
          l, ChildLimits{.parallel = 1, .queue = 1, .timeout = std::chrono::minutes(10)});
      std::error_code ec;
      auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
      code = std::make_unique<CodeApi>(l, *options.classroom, pairing, *tests,
                                       std::vector<std::string>{exe.string(), "try"}, *leagues,
                                       std::vector<std::string>{exe.string(), "league"});
    }
  }

  // The join code is needed unless the view is on loopback alone (and not behind a proxy).
  static bool needsCode(const ServerOptions& o) {
    beast::error_code ec;
    auto a = asio::ip::make_address(o.host, ec);
    return o.alwaysPair || !o.names.empty() || ec || !loopback(a);
  }

  struct Http;
  struct Socket;

  Loop& loop;
  Feed& feed;
  ServerOptions options;
  tcp::acceptor acceptor;
  asio::steady_timer retry;  // accept() again after a failure
  bool acceptFailing = false;
  bool stopped = false;
  std::list<std::weak_ptr<Http>> https;
  std::list<std::weak_ptr<Socket>> sockets;
  std::size_t open = 0;
  std::uint64_t phones = 0;  // the controller pages seen: each WebSocket a holder "phone#k"
  Pairing pairing;
  HostCheck hosts;                     // the names a Host may give (DNS rebinding)
  std::unique_ptr<ChildRuns> tests;    // --code: the Tests' children
  std::unique_ptr<ChildRuns> leagues;  // --code: the teacher's league
  std::unique_ptr<CodeApi> code;       // --code: the code page's requests

  void accept();
  void closeAll();
  void admit(tcp::socket socket);
  bool roomForSocket(const std::string& client, const std::function<bool()>& pairs);
  std::string driveUrl(std::string_view page = "drive") const;
};

// One WebSocket: the state, then updates paced to the rate, one write in flight at most.
struct Server::Impl::Socket : std::enable_shared_from_this<Socket> {
  Socket(std::shared_ptr<Impl> s, tcp::socket&& sock, std::string who)
      : server(std::move(s)),
        client(std::move(who)),
        ws(std::move(sock)),
        pace(server->loop.io()),
        stall(server->loop.io()),
        page(server->loop, server->feed, "phone#" + std::to_string(++server->phones),
             &server->pairing, client) {}

  std::shared_ptr<Impl> server;
  std::string client;  // whose slot this is (Pairing::clientKey of the address or forwarded one)
  websocket::stream<beast::tcp_stream> ws;
  asio::steady_timer pace, stall;
  beast::flat_buffer in;
  std::string out;                                // the message being written
  std::uint64_t lastChanges = ~std::uint64_t{0};  // the feed's changes() at the last update
  PageMessages page;  // what the page sends (a seat's holder), its answers before the next update
  std::uint64_t cursor = 0, trackSeen = 0;
  bool writing = false, closed = false;
  std::chrono::steady_clock::time_point lastWrite{};  // the last message written
  std::chrono::steady_clock::time_point lastLook{};   // the last update built (the pace)

  // `code`: the join code in the page's /ws?code=…, if any; `local`: a browser on this
  // machine, not forwarded (the race view beside the terminal), which is told the code.
  void start(http::request<http::string_body> request, std::optional<std::string> code,
             bool local) {
    server->open++;
    if (code) page.pair(*code);
    if (server->pairing.required() && (local || page.paired()))
      page.tell(nlohmann::json{
          {"type", "pairing"}, {"code", server->pairing.code()}, {"drive", server->driveUrl()}}
                    .dump());
    // A small send buffer: a browser that stops reading is noticed (and closed) in seconds,
    // not after the kernel has buffered megabytes of updates for it.
    beast::error_code ignored;
    beast::get_lowest_layer(ws).socket().set_option(asio::socket_base::send_buffer_size(64 * 1024),
                                                    ignored);
    // A WebSocket that answers no ping for kSocketIdle is closed: an idle squatter frees its
    // slot (a browser answers pings by itself, a page in the background too).
    auto timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.handshake_timeout = kRequestTimeout;
    timeouts.idle_timeout = kSocketIdle;
    timeouts.keep_alive_pings = true;
    ws.set_option(timeouts);
    ws.read_message_max(kMaxIncoming);
    ws.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
      self->server->feed.settle();
      nlohmann::json state = self->server->feed.state();
      self->cursor = self->server->feed.eventCursor();
      self->trackSeen = self->server->feed.trackVersion();
      self->write(state.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
      self->read();
    });
  }

  void read() {
    ws.async_read(in, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->close();
      std::string text = beast::buffers_to_string(self->in.data());
      self->in.consume(self->in.size());
      self->page.receive(text);
      self->read();
    });
  }

  void write(std::string text) {
    out = std::move(text);
    writing = true;
    lastWrite = lastLook = std::chrono::steady_clock::now();
    stall.expires_after(kWriteStall);
    stall.async_wait([weak = weak_from_this()](beast::error_code ec) {
      auto self = weak.lock();
      if (ec || !self || !self->writing) return;
      log::info("view", "a browser read nothing for 5 s: closed");
      self->close();
    });
    ws.text(true);
    ws.async_write(asio::buffer(out),
                   [self = shared_from_this()](beast::error_code ec, std::size_t) {
                     self->writing = false;
                     self->stall.cancel();
                     if (ec) return self->close();
                     self->next();
                   });
  }

  // The next update, no sooner than 1/rate after the last write began.
  void next() {
    if (closed) return;
    auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / std::max(server->options.maxRate, 0.1)));
    pace.expires_at(lastLook + period);
    pace.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closed) return;
      self->send();
    });
  }

  void send() {
    if (auto answer = page.nextAnswer()) return write(std::move(*answer));
    server->feed.settle();
    const Feed& feed = server->feed;
    bool unchanged = feed.changes() == lastChanges && feed.eventCursor() == cursor &&
                     feed.trackVersion() == trackSeen;
    if (unchanged && std::chrono::steady_clock::now() - lastWrite < kHeartbeat) {
      // nothing new: look again a period later, without writing
      lastLook = std::chrono::steady_clock::now();
      return next();
    }
    lastChanges = feed.changes();
    write(feed.updateText(cursor, trackSeen));  // the cars' part built once for every browser
  }

  void close() {
    if (closed) return;
    closed = true;
    server->open--;
    // a phone that goes (closed, lost, stalled) lets go of its seat: its car slows to a stop
    page.closed();
    pace.cancel();
    stall.cancel();
    beast::error_code ignored;
    beast::get_lowest_layer(ws).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws).socket().close(ignored);
  }
};

// One HTTP connection: files, /api/state, or the upgrade to /ws.
struct Server::Impl::Http : std::enable_shared_from_this<Http> {
  Http(std::shared_ptr<Impl> s, tcp::socket&& sock)
      : server(std::move(s)), stream(std::move(sock)) {}

  std::shared_ptr<Impl> server;
  beast::tcp_stream stream;
  beast::flat_buffer buffer;
  std::optional<http::request_parser<http::string_body>> parser;
  std::shared_ptr<void> response;  // kept alive while it is written
  std::string peer;                // the address it comes from (Pairing::clientKey)
  bool peerLoopback = false;
  bool closed = false;

  void read() {
    parser.emplace();
    parser->body_limit(server->code ? kMaxCodeBody : kMaxIncoming);
    parser->header_limit(16 * 1024);
    stream.expires_after(kRequestTimeout);  // a request (or the next on a kept-alive connection)
    http::async_read(
        stream, buffer, *parser, [self = shared_from_this()](beast::error_code ec, std::size_t) {
          // too large: said, then closed (nothing else of it is read)
          if (ec == http::error::header_limit)
            return self->refuse(http::status::request_header_fields_too_large,
                                "the request's header is over 16 KiB\n");
          if (ec == http::error::body_limit)
            return self->refuse(http::status::payload_too_large,
                                self->server->code ? "the view takes no body over 256 KiB\n"
                                                   : "the view takes no body over 64 KiB\n");
          if (ec) return self->close();
          self->handle(self->parser->release());
        });
  }

  // An answer to a request that is not read to its end; the connection closes after it.
  void refuse(http::status status, std::string body) {
    http::request<http::string_body> req;
    req.version(11);
    req.keep_alive(false);
    text(req, status, "text/plain", std::move(body));
  }

  template <class Body>
  void respond(http::response<Body>&& res) {
    auto sp = std::make_shared<http::response<Body>>(std::move(res));
    response = sp;
    stream.expires_after(kWriteStall);
    http::async_write(stream, *sp,
                      [self = shared_from_this(), sp](beast::error_code ec, std::size_t) {
                        self->response.reset();
                        if (ec || !sp->keep_alive()) return self->close();
                        self->read();
                      });
  }

  void text(const http::request<http::string_body>& req, http::status status, std::string_view type,
            std::string body) {
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::server, "pitwall");
    res.set(http::field::content_type, std::string(type));
    res.set(http::field::cache_control, "no-store");
    res.keep_alive(req.keep_alive());
    res.body() = std::move(body);
    res.prepare_payload();
    if (req.method() == http::verb::head) res.body().clear();  // the length stays, not the body
    respond(std::move(res));
  }

  // Who sent the request: the peer, or — through a --view-host proxy on this machine — the
  // last address the proxy put in X-Forwarded-For.
  std::string client(const http::request<http::string_body>& req, bool& forwarded) const {
    forwarded = false;
    auto host = req.find(http::field::host);
    if (!peerLoopback || host == req.end()) return peer;
    const std::string name = hostName(sv(host->value()));
    if (!server->hosts.proxied(name)) return peer;
    forwarded = true;
    auto xff = req.find("X-Forwarded-For");
    if (xff == req.end()) return peer;
    std::string_view list = sv(xff->value());
    std::string_view last =
        list.substr(list.rfind(',') == std::string_view::npos ? 0 : list.rfind(',') + 1);
    while (!last.empty() && last.front() == ' ') last.remove_prefix(1);
    while (!last.empty() && last.back() == ' ') last.remove_suffix(1);
    beast::error_code ec;
    auto a = asio::ip::make_address(std::string(last), ec);
    return ec ? peer : Pairing::clientKey(a.to_string());
  }

  // DNS rebinding: a page of another site whose name now resolves here sends its own name as
  // Host (and Origin); only the names the view serves are answered.
  std::optional<std::string> refusal(const http::request<http::string_body>& req) {
    auto header = [&](http::field field) -> std::optional<std::string_view> {
      auto it = req.find(field);
      if (it == req.end()) return std::nullopt;
      return sv(it->value());
    };
    return server->hosts.refusal(header(http::field::host), header(http::field::origin));
  }

  void handle(http::request<http::string_body> req) {
    std::string target(req.target());
    if (auto why = refusal(req))
      return text(req, http::status::forbidden, "text/plain", *why + "\n");
    if (websocket::is_upgrade(req)) {
      if (target != "/ws" && !target.starts_with("/ws?"))
        return text(req, http::status::not_found, "text/plain", "WebSocket only on /ws\n");
      bool forwarded = false;
      const std::string who = client(req, forwarded);
      std::optional<std::string> code;
      if (auto at = target.find("code="); at != std::string::npos) {
        auto end = target.find('&', at);
        code = target.substr(at + 5, end == std::string::npos ? std::string::npos : end - at - 5);
      }
      // A phone that brings the join code is never kept out by spectators: when the slots are
      // full it takes an unpaired page's. Its code is checked (and a wrong one counted) once,
      // here; the page pairs with it again without counting.
      auto pairs = [&] {
        return code && server->pairing.required() &&
               static_cast<bool>(server->pairing.check(who, *code, server->loop.seconds()));
      };
      if (!server->roomForSocket(who, pairs))
        return text(
            req, http::status::service_unavailable, "text/plain",
            "the view serves " + std::to_string(kMaxBrowsers) + " browsers at most; close one\n");
      stream.expires_never();
      auto socket = std::make_shared<Socket>(server, stream.release_socket(), who);
      server->sockets.push_back(socket);
      // local (shown the join code): this machine's own browser. Behind --view-host the proxy is
      // on loopback and may rewrite Host to 127.0.0.1 (nginx's default), so nobody is local then
      socket->start(std::move(req), std::move(code),
                    peerLoopback && !forwarded && server->options.names.empty());
      return;
    }
    if (target.starts_with("/api/code/")) {
      if (!server->code)
        return text(
            req, http::status::not_found, "application/json",
            R"({"error":"the code page is off: the run was started without --code FOLDER"})");
      return code(std::move(req));
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return text(req, http::status::method_not_allowed, "text/plain",
                  "only GET: the view is read-only\n");
    // a lap comparison (docs/view.md "Comparing two laps"): read-only, as /api/state
    if (target == "/api/laps")
      return text(
          req, http::status::ok, "application/json",
          lapList(server->feed).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    if (target.starts_with("/api/laps/compare?")) {
      auto compared = compareLaps(server->feed, std::string_view(target).substr(18));
      if (!compared)
        return text(req, http::status::bad_request, "application/json",
                    nlohmann::json{{"error", compared.error()}}.dump(
                        -1, ' ', false, nlohmann::json::error_handler_t::replace));
      return text(req, http::status::ok, "application/json",
                  compared->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    }
    if (target == "/api/state" || target.starts_with("/api/state?")) {
      server->feed.settle();
      return text(
          req, http::status::ok, "application/json",
          server->feed.state().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    }
    // the controller page (docs/view.md "The controller page"): a short address for a phone
    if (target == "/drive" || target.starts_with("/drive?")) target = "/drive.html";
    if (target == "/code" || target.starts_with("/code?")) {  // docs/classroom.md
      if (!server->code)
        return text(req, http::status::not_found, "text/plain",
                    "the code page is off: the run was started without --code FOLDER\n");
      target = "/code.html";
    }
    auto path = assetPath(server->options.assets, target);
    std::ifstream file;
    if (path) file.open(*path, std::ios::binary);
    if (!path || !file || std::filesystem::is_directory(*path))
      return text(req, http::status::not_found, "text/plain",
                  "not found: " + target.substr(0, 200) + "\n");
    std::ostringstream body;
    body << file.rdbuf();
    text(req, http::status::ok, contentType(*path), body.str());
  }

  // The code page's request (engine/view/code_api.hpp), answered now or when its Test has run.
  void code(http::request<http::string_body> req) {
    bool forwarded = false;
    CodeRequest r;
    r.method = std::string(req.method_string());
    r.target = std::string(req.target());
    r.body = std::move(req.body());
    if (auto a = req.find(http::field::authorization); a != req.end())
      r.authorization = std::string(sv(a->value()));
    r.client = client(req, forwarded);
    r.local = peerLoopback && !forwarded;
    const unsigned version = req.version();
    const bool keep = req.keep_alive();
    const bool head = req.method() == http::verb::head;
    server->code->handle(r, [self = shared_from_this(), version, keep, head](CodeReply reply) {
      if (self->closed) return;
      http::response<http::string_body> res{static_cast<http::status>(reply.status), version};
      res.set(http::field::server, "pitwall");
      res.set(http::field::content_type, reply.contentType);
      res.set(http::field::cache_control, "no-store");
      res.set("X-Content-Type-Options", "nosniff");
      if (!reply.filename.empty())
        res.set(http::field::content_disposition,
                "attachment; filename=\"" + reply.filename + "\"");
      res.keep_alive(keep);
      res.body() = std::move(reply.body);
      res.prepare_payload();
      if (head) res.body().clear();  // the length stays, not the body
      self->respond(std::move(res));
    });
  }

  void close() {
    closed = true;
    beast::error_code ignored;
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream.close();
  }
};

// Fair shares (docs/view.md "Limits"): when every HTTP slot is taken, the client that holds the
// most gives up its oldest connection (an idle keep-alive or a slow request, most often), so a
// squatter holding many cannot keep a newcomer out.
void Server::Impl::admit(tcp::socket socket) {
  beast::error_code ec;
  auto remote = socket.remote_endpoint(ec);
  if (ec) return;  // gone already
  auto http = std::make_shared<Http>(shared_from_this(), std::move(socket));
  http->peer = Pairing::clientKey(remote.address().to_string());
  http->peerLoopback = loopback(remote.address());
  std::erase_if(https, [](const auto& w) {
    auto h = w.lock();
    return !h || h->closed;
  });
  if (https.size() >= kMaxConnections) {
    std::map<std::string, std::size_t> count;
    for (auto& w : https) count[w.lock()->peer]++;
    auto most = std::max_element(count.begin(), count.end(),
                                 [](auto& a, auto& b) { return a.second < b.second; });
    for (auto& w : https)  // the list is oldest first
      if (auto h = w.lock(); h->peer == most->first) {
        h->close();
        break;
      }
    std::erase_if(https, [](const auto& w) {
      auto h = w.lock();
      return !h || h->closed;
    });
  }
  https.push_back(http);
  http->read();
}

// A WebSocket slot for `client`: free, or taken from the client that holds the most (more than
// `client` would): a socket of theirs that holds no seat first, the oldest first; else, when the
// newcomer brings the join code (`pairs()`), from the oldest page that is not paired, whoever's.
bool Server::Impl::roomForSocket(const std::string& client, const std::function<bool()>& pairs) {
  std::erase_if(sockets, [](const auto& w) {
    auto s = w.lock();
    return !s || s->closed;
  });
  if (open < kMaxBrowsers) return true;
  std::map<std::string, std::size_t> count;
  for (auto& w : sockets) count[w.lock()->client]++;
  auto most = std::max_element(count.begin(), count.end(),
                               [](auto& a, auto& b) { return a.second < b.second; });
  if (most == count.end() || most->second <= count[client] + 1) {
    if (!pairs()) return false;
    for (auto& w : sockets) {  // oldest first
      auto s = w.lock();
      if (s->page.paired()) continue;
      log::info("view", "a spectator's page of " + s->client + " closed to make room for " +
                            client + ", who brings the join code");
      s->close();
      return true;
    }
    return false;
  }
  const drive::Seats* seats = feed.seats();
  std::shared_ptr<Socket> victim;
  for (auto& w : sockets) {
    auto s = w.lock();
    if (s->client != most->first) continue;
    if (!victim) victim = s;
    if (!seats || !seats->heldBy(s->page.holder())) {
      victim = s;
      break;
    }
  }
  log::info("view", "a browser of " + most->first + " (which had " + std::to_string(most->second) +
                        ") closed to make room for " + client);
  victim->close();
  return true;
}

void Server::Impl::accept() {
  acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
    if (self->stopped || ec == asio::error::operation_aborted) return;
    if (ec) {
      // Out of file descriptors (EMFILE), buffers, memory: every accept() would fail at once
      // again, so waiting costs nothing and spinning would take the loop. Said once a streak.
      if (!self->acceptFailing)
        log::warn("view", "cannot take a browser's connection (" + ec.message() +
                              "): trying again every 250 ms");
      self->acceptFailing = true;
      self->retry.expires_after(kAcceptRetry);
      self->retry.async_wait([self](beast::error_code e) {
        if (!e && !self->stopped) self->accept();
      });
      return;
    }
    self->acceptFailing = false;
    self->admit(std::move(socket));
    self->accept();
  });
}

void Server::Impl::closeAll() {
  for (auto& w : sockets)
    if (auto s = w.lock()) s->close();
  for (auto& w : https)
    if (auto h = w.lock()) h->close();
  sockets.clear();
  https.clear();
}

Server::Server(Loop& loop, Feed& feed, ServerOptions options)
    : impl_(std::make_shared<Impl>(loop, feed, std::move(options))) {}

Server::~Server() {
  stop();
}

Result<bool, std::string> Server::start() {
  beast::error_code ec;
  auto address = asio::ip::make_address(impl_->options.host, ec);
  const std::string where = impl_->options.host + ":" + std::to_string(impl_->options.port);
  if (ec)
    return Unexpected{"--view " + where + ": '" + impl_->options.host +
                      "' is not an IP address (give 127.0.0.1, ::1, 0.0.0.0 or a local address)"};
  tcp::endpoint endpoint{address, impl_->options.port};
  auto& a = impl_->acceptor;
  a.open(endpoint.protocol(), ec);
  if (!ec) a.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(endpoint, ec);
  if (ec) {
    a.close();
    std::string why = ec == asio::error::address_in_use
                          ? "the port is in use (another pitwall, or another server): give "
                            "another with --view PORT, or --view 0 for any free port"
                          : ec.message();
    return Unexpected{"cannot serve the race view on " + where + ": " + why};
  }
  a.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return Unexpected{"cannot listen on " + where + ": " + ec.message()};
  // the names a browser may reach the view by (besides loopback and the machine's addresses)
  impl_->hosts.start(address.to_string(), impl_->options.names);
  impl_->accept();
  return true;
}

void Server::stop() {
  if (impl_->stopped) return;
  impl_->stopped = true;
  beast::error_code ignored;
  impl_->retry.cancel();
  impl_->acceptor.close(ignored);
  impl_->closeAll();
  // the code page's children (Tests, a league) are killed and reaped now: their replies hold
  // connections that hold this server, which would otherwise outlive the run with them
  impl_->code.reset();
  impl_->tests.reset();
  impl_->leagues.reset();
}

std::uint16_t Server::port() const {
  beast::error_code ec;
  auto ep = impl_->acceptor.local_endpoint(ec);
  return ec ? impl_->options.port : ep.port();
}

std::string Server::url() const {
  std::string host = impl_->options.host;
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  return "http://" + host + ":" + std::to_string(port()) + "/";
}

std::size_t Server::clients() const {
  return impl_->open;
}

std::string Server::joinCode() const {
  return impl_->pairing.required() ? impl_->pairing.code() : std::string();
}

std::string Server::driveUrl() const {
  return impl_->driveUrl();
}

std::string Server::viewUrl() const {
  return impl_->driveUrl("");
}

std::string Server::codeUrl() const {
  return impl_->options.classroom ? impl_->driveUrl("code") : std::string();
}

std::string Server::teacherUrl() const {
  if (!impl_->options.classroom) return {};
  // in the fragment: never sent in a request, never in a log; the page takes it out of the
  // address bar (a projected screen shows no key)
  return impl_->driveUrl("code") + "#teacher=" + impl_->options.classroom->teacherToken();
}

std::string Server::Impl::driveUrl(std::string_view page) const {
  // bound to every address: one a phone can reach (the first that is not loopback)
  std::string host = options.host;
  beast::error_code ec;
  auto bound = asio::ip::make_address(host, ec);
  if (!ec && bound.is_unspecified()) {
    std::string best;
    for (const auto& a : machineAddresses()) {
      auto addr = asio::ip::make_address(a, ec);
      if (ec || loopback(addr) || (addr.is_v6() && addr.to_v6().is_link_local())) continue;
      if (bound.is_v4() && !addr.is_v4()) continue;
      if (best.empty() || (addr.is_v4() && best.find(':') != std::string::npos)) best = a;
    }
    if (!best.empty()) host = best;
  }
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  auto ep = acceptor.local_endpoint(ec);
  std::string url = "http://" + host + ":" + std::to_string(ec ? options.port : ep.port()) + "/" +
                    std::string(page);
  if (pairing.required()) url += "?code=" + pairing.code();
  return url;
}

Result<ServerOptions, std::string> parseEndpoint(const std::string& text) {
  ServerOptions o;
  o.port = kDefaultPort;
  if (text.empty()) return o;
  std::string host = o.host, port = text;
  if (text.front() == '[') {  // [::1]:8080
    auto close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':')
      return Unexpected{"--view '" + text + "': write an IPv6 address as [ADDRESS]:PORT"};
    host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else if (auto colon = text.rfind(':'); colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (host == "localhost") host = "127.0.0.1";
  }
  unsigned value = 0;
  auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || value > 65535)
    return Unexpected{"--view '" + text + "': the port must be a number from 0 to 65535 (0: any " +
                      "free port), as in --view 8080 or --view 127.0.0.1:8080"};
  beast::error_code bad;
  asio::ip::make_address(host, bad);
  if (bad)
    return Unexpected{"--view '" + text + "': '" + host +
                      "' is not an IP address (give 127.0.0.1, ::1, 0.0.0.0 or a local address)"};
  o.host = host;
  o.port = static_cast<std::uint16_t>(value);
  return o;
}

}  // namespace pitwall::view
