#include "engine/view/server.hpp"

#include <unistd.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <charconv>
#include <fstream>
#include <list>
#include <sstream>

#include "engine/core/data_dir.hpp"
#include "engine/core/log.hpp"
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
constexpr auto kRequestTimeout = std::chrono::seconds(10);  // for a request to arrive whole
constexpr std::size_t kMaxBrowsers = 64;                    // WebSockets at once
constexpr std::size_t kMaxConnections = 128;  // HTTP connections at once (not upgraded)
constexpr auto kAcceptRetry = std::chrono::milliseconds(250);  // after a failed accept()

std::string_view contentType(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  return "application/octet-stream";
}

// A request's path mapped into the assets folder; none for anything that could leave it.
std::optional<std::filesystem::path> assetPath(const std::filesystem::path& root,
                                               std::string_view target) {
  if (auto q = target.find('?'); q != std::string_view::npos) target = target.substr(0, q);
  if (target.empty() || target[0] != '/') return std::nullopt;
  std::string rel(target.substr(1));
  if (rel.empty()) rel = "index.html";
  for (char c : rel)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' ||
          c == '/'))
      return std::nullopt;
  // never absolute (root / "/etc/passwd" is /etc/passwd), never up, never empty parts
  if (rel.front() == '/' || rel.find("..") != std::string::npos ||
      rel.find("//") != std::string::npos)
    return std::nullopt;
  return root / rel;
}

}  // namespace

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
  Impl(Loop& l, Feed& f, ServerOptions o)
      : loop(l), feed(f), options(std::move(o)), acceptor(l.io()), retry(l.io()) {}

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

  void accept();
  void closeAll();
};

// One WebSocket: the state, then updates paced to the rate, one write in flight at most.
struct Server::Impl::Socket : std::enable_shared_from_this<Socket> {
  Socket(std::shared_ptr<Impl> s, tcp::socket&& sock)
      : server(std::move(s)),
        ws(std::move(sock)),
        pace(server->loop.io()),
        stall(server->loop.io()),
        page(server->loop, server->feed, "phone#" + std::to_string(++server->phones)) {}

  std::shared_ptr<Impl> server;
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

  void start(http::request<http::string_body> request) {
    server->open++;
    // A small send buffer: a browser that stops reading is noticed (and closed) in seconds,
    // not after the kernel has buffered megabytes of updates for it.
    beast::error_code ignored;
    beast::get_lowest_layer(ws).socket().set_option(asio::socket_base::send_buffer_size(64 * 1024),
                                                    ignored);
    ws.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws.read_message_max(kMaxIncoming);
    ws.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close();
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

  void read() {
    parser.emplace();
    parser->body_limit(kMaxIncoming);
    parser->header_limit(16 * 1024);
    stream.expires_after(kRequestTimeout);  // a request (or the next on a kept-alive connection)
    http::async_read(stream, buffer, *parser,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       // too large: said, then closed (nothing else of it is read)
                       if (ec == http::error::header_limit)
                         return self->refuse(http::status::request_header_fields_too_large,
                                             "the request's header is over 16 KiB\n");
                       if (ec == http::error::body_limit)
                         return self->refuse(http::status::payload_too_large,
                                             "the view takes no body over 64 KiB\n");
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

  void handle(http::request<http::string_body> req) {
    std::string target(req.target());
    if (websocket::is_upgrade(req)) {
      if (target != "/ws")
        return text(req, http::status::not_found, "text/plain", "WebSocket only on /ws\n");
      // Only the view's own page: another site open in the same browser may not connect (it
      // could not be stopped from sending what it likes). Tools that are no browser send no
      // Origin.
      if (auto origin = req.find(http::field::origin); origin != req.end()) {
        auto host = req.find(http::field::host);
        if (host == req.end() ||
            std::string(origin->value()) != "http://" + std::string(host->value()))
          return text(req, http::status::forbidden, "text/plain",
                      "the race view's WebSocket is for its own page, not for " +
                          std::string(origin->value()).substr(0, 200) + "\n");
      }
      if (server->open >= kMaxBrowsers)
        return text(
            req, http::status::service_unavailable, "text/plain",
            "the view serves " + std::to_string(kMaxBrowsers) + " browsers at most; close one\n");
      stream.expires_never();
      auto socket = std::make_shared<Socket>(server, stream.release_socket());
      server->sockets.push_back(socket);
      socket->start(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return text(req, http::status::method_not_allowed, "text/plain",
                  "only GET: the view is read-only\n");
    if (target == "/api/state" || target.starts_with("/api/state?"))
      return text(
          req, http::status::ok, "application/json",
          server->feed.state().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    // the controller page (docs/view.md "The controller page"): a short address for a phone
    if (target == "/drive" || target.starts_with("/drive?")) target = "/drive.html";
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

  void close() {
    beast::error_code ignored;
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream.close();
  }
};

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
    self->https.remove_if([](const auto& w) { return w.expired(); });
    self->sockets.remove_if([](const auto& w) { return w.expired(); });
    if (self->https.size() >= kMaxConnections) {
      beast::error_code ignored;  // more connections than any audience: this one is closed
      socket.close(ignored);
    } else {
      auto http = std::make_shared<Http>(self, std::move(socket));
      self->https.push_back(http);
      http->read();
    }
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

Result<std::filesystem::path, std::string> findAssets() {
  std::vector<std::filesystem::path> places;
  if (const char* env = std::getenv("PITWALL_VIEW_DIR"); env && *env) places.emplace_back(env);
  for (const auto& data : dataDirCandidates()) places.push_back(data / "web");
  std::string looked;
  for (const auto& p : places) {
    std::error_code ec;
    if (std::filesystem::exists(p / "index.html", ec))
      return std::filesystem::weakly_canonical(p, ec);
    looked += (looked.empty() ? "" : ", ") + p.string();
  }
  return Unexpected{
      "the race view's page is not installed (looked in " + looked +
      "); build it (./dev build), install pitwall, or set PITWALL_VIEW_DIR to its folder"};
}

}  // namespace pitwall::view
