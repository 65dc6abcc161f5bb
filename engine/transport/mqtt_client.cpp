#include "engine/transport/mqtt_client.hpp"

#include "engine/core/numbers.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <mosquitto.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "engine/core/log.hpp"

namespace pitwall {

namespace {

constexpr Duration kMiscPeriod = std::chrono::milliseconds(100);
constexpr Duration kFirstBackoff = std::chrono::milliseconds(500);
constexpr Duration kMaxBackoff = std::chrono::seconds(8);
constexpr Duration kAttemptTimeout = std::chrono::seconds(10);
constexpr std::size_t kMaxPayload = 268435455;  // MQTT 3.1.1 §2.2.3: the largest remaining length

void initLibrary() {
  static std::once_flag once;
  std::call_once(once, [] { mosquitto_lib_init(); });
}

void checkQos(int qos, std::string_view what) {
  if (qos < 0 || qos > 2)
    throw std::invalid_argument(std::string(what) + ": " + outOfRange("QoS", qos, 0, 2));
}

void checkPublishTopic(std::string_view topic, std::string_view what) {
  std::string t(topic);
  if (t.empty() || mosquitto_pub_topic_check(t.c_str()) != MOSQ_ERR_SUCCESS ||
      mosquitto_validate_utf8(t.data(), static_cast<int>(t.size())) != MOSQ_ERR_SUCCESS)
    throw std::invalid_argument(std::string(what) + ": '" + t +
                                "' is not a valid MQTT topic (it must be non-empty UTF-8 "
                                "without the wildcards + and #)");
}

// Sets what a connection needs from the options (no delay, credentials, TLS, the will) on a new
// client; an error sentence, or empty.
std::string configure(mosquitto* mosq, const MqttOptions& o) {
  std::string error;
  auto check = [&](int rc, const std::string& what) {
    if (rc == MOSQ_ERR_SUCCESS || !error.empty()) return;
    error = "MQTT: " + what + ": " + mosquitto_strerror(rc);
  };
  // Nagle's algorithm holds a small packet while an earlier one is unacknowledged, and the peer
  // delays its ACK (Linux: 40 ms): a burst of publications would wait that long
  // (docs/performance.md "MQTT bridge"). Bursts are coalesced with Batch instead.
  check(mosquitto_int_option(mosq, MOSQ_OPT_TCP_NODELAY, 1), "cannot set TCP_NODELAY");
  if (!o.username.empty())
    check(mosquitto_username_pw_set(mosq, o.username.c_str(),
                                    o.password.empty() ? nullptr : o.password.c_str()),
          "cannot set the username");
  if (o.tls) {
    if (o.caFile.empty())
      check(mosquitto_int_option(mosq, MOSQ_OPT_TLS_USE_OS_CERTS, 1), "cannot use the OS CAs");
    else
      check(mosquitto_tls_set(mosq, o.caFile.c_str(), nullptr, nullptr, nullptr, nullptr),
            "cannot use the CA file '" + o.caFile + "'");
  }
  if (o.will)
    check(mosquitto_will_set(mosq, o.will->topic.c_str(), static_cast<int>(o.will->payload.size()),
                             o.will->payload.data(), o.will->qos, o.will->retain),
          "cannot set the last will");
  return error;
}

}  // namespace

Result<MqttUrl, std::string> parseMqttUrl(std::string_view url) {
  auto bad = [&](const std::string& why) {
    return Unexpected(std::string("bad MQTT URL '") + std::string(url) + "': " + why +
                      " (expected mqtt://HOST[:PORT] or mqtts://HOST[:PORT])");
  };
  MqttUrl out;
  std::string_view rest;
  if (url.substr(0, 7) == "mqtt://") {
    rest = url.substr(7);
  } else if (url.substr(0, 8) == "mqtts://") {
    rest = url.substr(8);
    out.tls = true;
    out.port = 8883;
  } else {
    auto scheme = url.find("://");
    return bad(scheme == std::string_view::npos
                   ? "no scheme"
                   : "unknown scheme '" + std::string(url.substr(0, scheme)) + "'");
  }
  if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);  // mqtt://host:1883/ is common
  if (rest.find('@') != std::string_view::npos)
    return bad("credentials in the URL are not supported; give the username and password apart");
  if (auto p = rest.find_first_of("/?#"); p != std::string_view::npos)
    return bad("unexpected '" + std::string(rest.substr(p)) + "' after the host and port");
  std::string_view host = rest, port;
  if (!rest.empty() && rest.front() == '[') {  // [IPv6]:PORT
    auto close = rest.find(']');
    if (close == std::string_view::npos) return bad("unclosed '[' in the host");
    host = rest.substr(1, close - 1);
    auto after = rest.substr(close + 1);
    if (!after.empty()) {
      if (after.front() != ':') return bad("expected ':PORT' after ']'");
      port = after.substr(1);
      if (port.empty()) return bad("empty port after ':'");
    }
  } else if (auto colon = rest.rfind(':'); colon != std::string_view::npos) {
    host = rest.substr(0, colon);
    port = rest.substr(colon + 1);
    if (port.empty()) return bad("empty port after ':'");
    if (host.find(':') != std::string_view::npos)
      return bad("an IPv6 address must be written in brackets, as [::1]");
  }
  if (host.empty()) return bad("no host");
  out.host = std::string(host);
  if (!port.empty()) {
    int value = 0;
    auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (ec != std::errc() || end != port.data() + port.size() || value < 1 || value > 65535)
      return bad("port '" + std::string(port) + "' is not a number from 1 to 65535");
    out.port = value;
  }
  return out;
}

MqttOptions MqttOptions::fromUrl(std::string_view url) {
  auto parsed = parseMqttUrl(url);
  if (!parsed) throw std::invalid_argument(parsed.error());
  MqttOptions o;
  o.host = parsed->host;
  o.port = parsed->port;
  o.tls = parsed->tls;
  return o;
}

MqttClient::MqttClient(Loop& loop, MqttOptions options)
    : loop_(loop), options_(std::move(options)), fd_(loop.io()) {
  auto& o = options_;
  if (loop.clockKind() != ClockKind::Real)
    throw std::invalid_argument("the MQTT client needs a loop on the real clock");
  if (o.host.empty()) throw std::invalid_argument("MQTT: no broker host given");
  if (o.port < 1 || o.port > 65535)
    throw std::invalid_argument("MQTT: " + outOfRange("port", o.port, 1, 65535));
  if (o.keepaliveSeconds < 5 || o.keepaliveSeconds > 65535)
    throw std::invalid_argument("MQTT: " +
                                outOfRange("keepalive", o.keepaliveSeconds, 5, 65535, "s"));
  if (o.clientId.size() > 65535) throw std::invalid_argument("MQTT: the client id is too long");
  if (o.username.empty() && !o.password.empty())
    throw std::invalid_argument("MQTT: a password was given without a username");
  if (!o.caFile.empty() && !o.tls)
    throw std::invalid_argument("MQTT: a CA file was given but TLS is off (use mqtts://)");
  if (!o.caFile.empty() && ::access(o.caFile.c_str(), R_OK) != 0)
    throw std::invalid_argument("MQTT: cannot read the CA file '" + o.caFile +
                                "': " + std::strerror(errno));
  if (o.will) {
    checkPublishTopic(o.will->topic, "MQTT last will");
    checkQos(o.will->qos, "MQTT last will");
    if (o.will->payload.size() > kMaxPayload)
      throw std::invalid_argument("MQTT last will: the payload is too large");
  }

  initLibrary();
  mosq_ = mosquitto_new(o.clientId.empty() ? nullptr : o.clientId.c_str(), true, this);
  if (!mosq_) throw std::runtime_error("MQTT: cannot make a mosquitto client (out of memory)");
  mosquitto_connect_callback_set(mosq_, &MqttClient::handleConnect);
  mosquitto_disconnect_callback_set(mosq_, &MqttClient::handleDisconnect);
  mosquitto_message_callback_set(mosq_, &MqttClient::handleMessage);
  mosquitto_log_callback_set(mosq_, &MqttClient::handleLog);
  mosquitto_publish_callback_set(mosq_, &MqttClient::handlePublish);
  if (std::string error = configure(mosq_, o); !error.empty()) {
    mosquitto_destroy(mosq_);
    throw std::invalid_argument(error);
  }
}

MqttClient::~MqttClient() {
  *alive_ = false;
  for (auto* t : {&miscTimer_, &retryTimer_, &attemptTimer_})
    if (*t) loop_.cancel(*t);
  for (auto& w : deliveryWaiters_) loop_.cancel(w->timer);
  detachSocket();
  mosquitto_destroy(mosq_);  // closes the socket without DISCONNECT
}

std::string MqttClient::where() const {
  return std::string(options_.tls ? "mqtts://" : "mqtt://") + options_.host + ":" +
         std::to_string(options_.port);
}

void MqttClient::connect() {
  if (state_ == State::Connecting || state_ == State::Connected ||
      state_ == State::WaitingToReconnect)
    return;
  bool first = state_ == State::Idle;
  backoff_ = kFirstBackoff;
  lastReported_.clear();
  startAttempt(first);
}

void MqttClient::startAttempt(bool first) {
  detachSocket();
  state_ = State::Connecting;
  refused_ = false;
  wasConnected_ = false;
  lastLogError_.clear();
  errno = 0;
  // Name resolution inside connect_async is blocking (getaddrinfo); instant for an address or
  // /etc/hosts, the usual case for a broker.
  int rc = first ? mosquitto_connect_async(mosq_, options_.host.c_str(), options_.port,
                                           options_.keepaliveSeconds)
                 : mosquitto_reconnect_async(mosq_);
  if (rc != MOSQ_ERR_SUCCESS) {
    // a loopback TLS handshake can fail inside connect_async already
    std::string why = describe(rc, errno);
    return lost("cannot connect to the MQTT broker at " + where() + ": " + why, why);
  }
  attachSocket();
  tcpPending_ = true;
  std::weak_ptr<bool> alive = alive_;
  attemptTimer_ = loop_.after(kAttemptTimeout, [this, alive] {
    if (alive.expired()) return;
    attemptTimer_ = 0;
    if (state_ != State::Connecting) return;
    detachSocket();  // mosquitto closes it on the next attempt
    std::string why =
        "no answer within " +
        std::to_string(std::chrono::duration_cast<std::chrono::seconds>(kAttemptTimeout).count()) +
        " s";
    lost("cannot connect to the MQTT broker at " + where() + ": " + why, why);
  });
  scheduleMisc();
  service();
}

std::string MqttClient::describe(int rc, int savedErrno) const {
  std::string why;
  if (rc == MOSQ_ERR_ERRNO && savedErrno)
    why = std::strerror(savedErrno);
  else if (rc == MOSQ_ERR_EAI)
    why = "cannot resolve the host name";
  else if (rc == MOSQ_ERR_TLS || rc == MOSQ_ERR_TLS_HANDSHAKE)
    why = lastLogError_.empty()
              ? "TLS handshake failed (is the CA file the one that signed the broker's "
                "certificate, and does that certificate name the host?)"
              : "TLS handshake failed";
  else if (rc == MOSQ_ERR_KEEPALIVE)
    why = "no answer within the keepalive time";
  else
    why = mosquitto_strerror(rc);
  // OpenSSL's reason for a failed handshake reaches us only as a log line
  if (!lastLogError_.empty() && !wasConnected_) why += " (" + lastLogError_ + ")";
  return why;
}

void MqttClient::attachSocket() {
  int fd = mosquitto_socket(mosq_);
  if (fd < 0) return;
  ++generation_;
  fd_.assign(fd);
  readWaiting_ = writeWaiting_ = false;
}

void MqttClient::detachSocket() {
  ++generation_;
  readWaiting_ = writeWaiting_ = false;
  tcpPending_ = false;
  if (!fd_.is_open()) return;
  boost::system::error_code ec;
  fd_.cancel(ec);
  fd_.release();  // mosquitto owns the descriptor and closes it
}

void MqttClient::service() {
  if (inService_) return;  // a callback inside loop_read published: the outer call re-arms
  inService_ = true;
  // Serve while the socket is ready (checked with poll, so nothing depends on whether the
  // reactor reports edges or levels); bounded so one busy broker cannot starve the loop.
  for (int i = 0; i < 64 && fd_.is_open(); ++i) {
    auto gen = generation_;
    pollfd p{fd_.native_handle(), POLLIN, 0};
    if (tcpPending_ || mosquitto_want_write(mosq_)) p.events |= POLLOUT;
    if (::poll(&p, 1, 0) <= 0) break;
    if (p.revents & POLLOUT) {
      tcpPending_ = false;
      int rc = mosquitto_loop_write(mosq_, 1);
      if (gen != generation_) break;
      if (rc != MOSQ_ERR_SUCCESS) return failed(rc);
    }
    if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
      int rc = mosquitto_loop_read(mosq_, 1);
      if (gen != generation_) break;
      // mosquitto 2.0.11 returns a failed TLS handshake (want_connect) without calling the
      // disconnect callback and without closing the socket: handled here as a loss
      if (rc != MOSQ_ERR_SUCCESS) return failed(rc);
    }
  }
  inService_ = false;
  arm();
}

void MqttClient::failed(int rc) {
  inService_ = false;
  handleDisconnect(mosq_, this, rc);
}

void MqttClient::arm() {
  if (!fd_.is_open()) return;
  using W = boost::asio::posix::stream_descriptor;
  std::weak_ptr<bool> alive = alive_;
  auto gen = generation_;
  auto wait = [&](W::wait_type type, bool& waiting) {
    if (waiting) return;
    waiting = true;
    fd_.async_wait(type, [this, alive, gen, &waiting](const boost::system::error_code& ec) {
      if (alive.expired() || gen != generation_) return;
      waiting = false;
      if (ec) return;
      service();
    });
  };
  wait(W::wait_read, readWaiting_);
  if (tcpPending_ || mosquitto_want_write(mosq_)) wait(W::wait_write, writeWaiting_);
}

void MqttClient::scheduleMisc() {
  if (miscTimer_) return;
  std::weak_ptr<bool> alive = alive_;
  miscTimer_ = loop_.after(kMiscPeriod, [this, alive] {
    if (alive.expired()) return;
    miscTimer_ = 0;
    if (!fd_.is_open()) return;
    mosquitto_loop_misc(mosq_);  // keepalive PINGREQ, a dead link detected, QoS retries
    service();
    if (fd_.is_open()) scheduleMisc();
  });
}

void MqttClient::report(const std::string& reason, bool retrying) {
  // A broker that stays away is reported once, not at every attempt.
  if (retrying && reason == lastReported_) return;
  lastReported_ = reason;
  if (state_ == State::Disconnected)  // on request
    log::info("mqtt", reason);
  else
    log::warn("mqtt", reason + (retrying ? "; retrying" : ""));
  if (onDisconnected) onDisconnected(reason, retrying);
}

void MqttClient::lost(const std::string& reason, const std::string& why) {
  failure_ = why;
  if (attemptTimer_) loop_.cancel(attemptTimer_), attemptTimer_ = 0;
  state_ = State::WaitingToReconnect;
  unacknowledged_.clear();
  settleDeliveries();
  report(reason, true);
  std::weak_ptr<bool> alive = alive_;
  if (retryTimer_) loop_.cancel(retryTimer_);
  retryTimer_ = loop_.after(backoff_, [this, alive] {
    if (alive.expired()) return;
    retryTimer_ = 0;
    if (state_ == State::WaitingToReconnect) startAttempt(false);
  });
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
}

void MqttClient::disconnect() {
  for (auto* t : {&retryTimer_, &attemptTimer_})
    if (*t) loop_.cancel(*t), *t = 0;
  bool open = fd_.is_open();
  state_ = State::Disconnected;
  if (!open) return;
  // DISCONNECT is written now when the socket takes it (the usual case) and the disconnect
  // callback follows; otherwise it is queued and service() writes it.
  if (mosquitto_disconnect(mosq_) != MOSQ_ERR_SUCCESS) detachSocket();
  service();
}

bool MqttClient::publish(std::string_view topic, std::string_view payload, int qos, bool retain) {
  checkPublishTopic(topic, "MQTT publish");
  checkQos(qos, "MQTT publish to '" + std::string(topic) + "'");
  if (payload.size() > kMaxPayload)
    throw std::invalid_argument("MQTT publish to '" + std::string(topic) + "': payload of " +
                                std::to_string(payload.size()) + " bytes is too large");
  if (state_ != State::Connected) return false;
  std::string t(topic);
  int mid = 0;
  int rc = mosquitto_publish(mosq_, &mid, t.c_str(), static_cast<int>(payload.size()),
                             payload.data(), qos, retain);
  if (rc == MOSQ_ERR_SUCCESS && qos > 0) unacknowledged_.insert(mid);
  service();
  return rc == MOSQ_ERR_SUCCESS;
}

void MqttClient::subscribe(std::string_view pattern, int qos) {
  std::string p(pattern);
  if (p.empty() || mosquitto_sub_topic_check(p.c_str()) != MOSQ_ERR_SUCCESS ||
      mosquitto_validate_utf8(p.data(), static_cast<int>(p.size())) != MOSQ_ERR_SUCCESS)
    throw std::invalid_argument("MQTT subscribe: '" + p +
                                "' is not a valid topic filter (+ stands for one whole level, "
                                "# only for the last)");
  checkQos(qos, "MQTT subscribe to '" + p + "'");
  subscriptions_[p] = qos;
  if (state_ != State::Connected) return;  // sent on connection
  mosquitto_subscribe(mosq_, nullptr, p.c_str(), qos);
  service();
}

void MqttClient::handleConnect(mosquitto*, void* self, int rc) {
  auto& c = *static_cast<MqttClient*>(self);
  if (c.attemptTimer_) c.loop_.cancel(c.attemptTimer_), c.attemptTimer_ = 0;
  if (rc != 0) {
    // The broker closes the connection next; the disconnect callback must not retry.
    c.refused_ = true;
    c.state_ = State::Failed;
    c.failure_ = std::string("refused: ") + mosquitto_connack_string(rc);
    c.report("the MQTT broker at " + c.where() +
                 " refused the connection: " + mosquitto_connack_string(rc),
             false);
    return;
  }
  c.state_ = State::Connected;
  c.wasConnected_ = true;
  c.failure_.clear();
  c.backoff_ = kFirstBackoff;
  c.lastReported_.clear();
  // A clean session forgets subscriptions: every connection makes them again.
  for (const auto& [pattern, qos] : c.subscriptions_)
    mosquitto_subscribe(c.mosq_, nullptr, pattern.c_str(), qos);
  log::info("mqtt", "connected to " + c.where());
  if (c.onConnected) c.onConnected();
}

void MqttClient::handleDisconnect(mosquitto*, void* self, int rc) {
  auto& c = *static_cast<MqttClient*>(self);
  int savedErrno = errno;
  // mosquitto 2.0.11 closes the socket just before this callback on most paths (after it on
  // others); the descriptor is released, never closed by Asio, and on one thread the number
  // cannot be reused in between.
  c.detachSocket();
  c.unacknowledged_.clear();  // a clean session: they will never be acknowledged now
  c.settleDeliveries();
  if (c.state_ == State::Disconnected) {
    c.report("disconnected from the MQTT broker at " + c.where() + " on request", false);
    return;
  }
  if (c.refused_) return;  // reported with the CONNACK's reason
  std::string why = c.describe(rc, savedErrno);
  c.lost((c.wasConnected_ ? "lost the connection to the MQTT broker at "
                          : "cannot connect to the MQTT broker at ") +
             c.where() + ": " + why,
         why);
}

MqttClient::Batch::Batch(MqttClient& client) : client_(client) {
  if (client_.batchDepth_++ > 0 || client_.state_ != State::Connected) return;
  int fd = mosquitto_socket(client_.mosq_);
  int one = 1;
  if (fd >= 0 && ::setsockopt(fd, IPPROTO_TCP, TCP_CORK, &one, sizeof one) == 0) corked_ = fd;
}

MqttClient::Batch::~Batch() {
  --client_.batchDepth_;
  if (corked_ < 0) return;
  // Uncorking sends what was held at once; the socket may have changed meanwhile (a loss): then
  // the held bytes went with the old one.
  int zero = 0;
  if (mosquitto_socket(client_.mosq_) == corked_)
    ::setsockopt(corked_, IPPROTO_TCP, TCP_CORK, &zero, sizeof zero);
}

void MqttClient::handlePublish(mosquitto*, void* self, int mid) {
  auto& c = *static_cast<MqttClient*>(self);
  c.unacknowledged_.erase(mid);
  c.settleDeliveries();
}

void MqttClient::whenDelivered(std::function<void()> done, Duration limit) {
  auto waiter = std::make_shared<DeliveryWaiter>();
  waiter->done = std::move(done);
  std::weak_ptr<bool> alive = alive_;
  waiter->timer = loop_.after(limit, [this, alive, w = std::weak_ptr<DeliveryWaiter>(waiter)] {
    auto waiter = w.lock();
    if (alive.expired() || !waiter) return;
    waiter->timer = 0;
    std::erase(deliveryWaiters_, waiter);
    if (waiter->done) waiter->done();
  });
  deliveryWaiters_.push_back(std::move(waiter));
  // Called from the loop, never from inside the caller's own call.
  loop_.post([this, alive] {
    if (!alive.expired()) settleDeliveries();
  });
}

void MqttClient::settleDeliveries() {
  if ((!unacknowledged_.empty() && state_ == State::Connected) || deliveryWaiters_.empty()) return;
  auto waiters = std::move(deliveryWaiters_);
  deliveryWaiters_.clear();
  for (auto& w : waiters) {
    loop_.cancel(w->timer);
    w->timer = 0;
    if (w->done) w->done();
  }
}

void MqttClient::handleMessage(mosquitto*, void* self, const mosquitto_message* m) {
  auto& c = *static_cast<MqttClient*>(self);
  if (!c.onMessage) return;
  std::string_view payload(static_cast<const char*>(m->payload),
                           static_cast<std::size_t>(std::max(m->payloadlen, 0)));
  // An exception must not unwind through libmosquitto's C frames. The handlers catch what a
  // message makes them throw (docs/mqtt.md "Hostile input"); this is the last resort.
  try {
    c.onMessage(m->topic, payload, m->retain);
  } catch (const std::exception& e) {
    log::warn("mqtt", "dropped a message on " + std::string(m->topic).substr(0, 200) + " (" +
                          std::to_string(payload.size()) + " bytes): its handler threw " +
                          std::string(e.what()).substr(0, 200));
  } catch (...) {
    log::warn("mqtt", "dropped a message on " + std::string(m->topic).substr(0, 200) + " (" +
                          std::to_string(payload.size()) + " bytes): its handler threw");
  }
}

void MqttClient::handleLog(mosquitto*, void* self, int level, const char* text) {
  // OpenSSL's reasons for a failed handshake reach us only as log lines.
  if (level & (MOSQ_LOG_ERR | MOSQ_LOG_WARNING))
    static_cast<MqttClient*>(self)->lastLogError_ = text;
}

bool publishOnce(const MqttOptions& options, const std::string& topic, const std::string& payload,
                 int qos, std::chrono::milliseconds limit) {
  initLibrary();
  MqttOptions o = options;
  o.will.reset();  // a goodbye of its own would be the main connection's will twice
  struct Progress {
    int connected = -1;  // the CONNACK's code once it came
    int mid = -1;
    bool delivered = false;
  } progress;
  mosquitto* mosq = mosquitto_new(nullptr, true, &progress);  // a random client id of its own
  if (!mosq) return false;
  mosquitto_connect_callback_set(
      mosq, [](mosquitto*, void* p, int rc) { static_cast<Progress*>(p)->connected = rc; });
  mosquitto_publish_callback_set(mosq, [](mosquitto*, void* p, int mid) {
    auto* progress = static_cast<Progress*>(p);
    if (mid == progress->mid) progress->delivered = true;
  });
  const auto deadline = std::chrono::steady_clock::now() + limit;
  auto within = [&] { return std::chrono::steady_clock::now() < deadline; };
  bool sent = false;
  if (configure(mosq, o).empty() &&
      mosquitto_connect_async(mosq, o.host.c_str(), o.port, 5) == MOSQ_ERR_SUCCESS) {
    while (within() && progress.connected < 0)
      if (mosquitto_loop(mosq, 20, 1) != MOSQ_ERR_SUCCESS) break;
    if (progress.connected == 0 &&
        mosquitto_publish(mosq, &progress.mid, topic.c_str(), static_cast<int>(payload.size()),
                          payload.data(), qos, false) == MOSQ_ERR_SUCCESS) {
      // QoS 0 is out once written; QoS 1 and 2 once the broker acknowledged
      while (within() && !progress.delivered)
        if (mosquitto_loop(mosq, 20, 1) != MOSQ_ERR_SUCCESS) break;
      sent = progress.delivered;
      mosquitto_disconnect(mosq);
      mosquitto_loop(mosq, 20, 1);
    }
  }
  mosquitto_destroy(mosq);
  return sent;
}

}  // namespace pitwall
