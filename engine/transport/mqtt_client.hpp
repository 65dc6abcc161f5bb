#pragma once
// An MQTT client (libmosquitto 2.0) driven from the engine's one loop: no mosquitto thread.
//
// mosquitto's socket waits in an asio::posix::stream_descriptor (read always, write while
// mosquitto_want_write); readiness calls mosquitto_loop_read/_write; mosquitto_loop_misc (keepalive
// pings, QoS retries) runs on a loop timer. mosquitto's callbacks therefore arrive on the loop
// thread, inside those calls. After an unexpected loss the client reconnects with backoff (0.5 s
// doubling to 8 s) and re-subscribes what was subscribed. docs/mqtt.md describes the design.
#include <boost/asio/posix/stream_descriptor.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"

struct mosquitto;
struct mosquitto_message;

namespace pitwall {

// mqtt://HOST[:PORT] (default 1883) or mqtts://HOST[:PORT] (TLS, default 8883).
struct MqttUrl {
  std::string host;
  int port = 1883;
  bool tls = false;
};
// An error names what is wrong with which part of the URL.
Result<MqttUrl, std::string> parseMqttUrl(std::string_view url);

struct MqttWill {
  std::string topic;
  std::string payload;
  int qos = 0;
  bool retain = false;
};

struct MqttOptions {
  std::string host = "127.0.0.1";
  int port = 1883;
  std::string clientId;  // empty: mosquitto makes a random one
  int keepaliveSeconds = 30;
  std::string username;  // empty: no credentials
  std::string password;
  bool tls = false;
  std::string caFile;  // with tls: the CA that signed the broker's certificate (PEM)
  std::optional<MqttWill> will;

  // Sets host, port and tls from a URL; throws std::invalid_argument on a bad URL.
  static MqttOptions fromUrl(std::string_view url);
};

class MqttClient {
 public:
  enum class State { Idle, Connecting, Connected, WaitingToReconnect, Failed, Disconnected };

  // Throws std::invalid_argument for bad options (port, keepalive, will, TLS without CA file...).
  // The loop must run on a real clock and outlive the client.
  MqttClient(Loop& loop, MqttOptions options);
  ~MqttClient();  // drops the connection without DISCONNECT: the broker sends the will
  MqttClient(const MqttClient&) = delete;
  MqttClient& operator=(const MqttClient&) = delete;

  // Events, called on the loop. onDisconnected carries a sentence saying why, and whether the
  // client will try again (false after a refusal by the broker, or after disconnect()).
  std::function<void()> onConnected;
  std::function<void(const std::string& reason, bool retrying)> onDisconnected;
  std::function<void(std::string_view topic, std::string_view payload, bool retained)> onMessage;

  // Starts connecting; returns at once. Failures arrive through onDisconnected.
  void connect();
  // Sends DISCONNECT (the broker discards the will) and stops reconnecting.
  void disconnect();

  // Throws std::invalid_argument for a bad topic or QoS. Returns false (nothing queued) when not
  // connected.
  bool publish(std::string_view topic, std::string_view payload, int qos = 0, bool retain = false);
  // While a Batch lives, what is published leaves in as few TCP segments as the kernel can make
  // (TCP_CORK): a car's position update is 10 publications. Nests; harmless when not connected.
  class Batch {
   public:
    explicit Batch(MqttClient& client);
    ~Batch();
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

   private:
    MqttClient& client_;
    int corked_ = -1;
  };

  // Calls done() on the loop once every QoS 1/2 message published so far on this connection is
  // acknowledged by the broker, the connection is gone (they never will be), or `limit` passed.
  // A clean goodbye publishes, waits for this, then disconnect()s: a broker whose PUBACK meets
  // a closed socket drops the rest of what was sent.
  void whenDelivered(std::function<void()> done, Duration limit = std::chrono::seconds(2));

  // Remembered and (re)sent on every connection. Throws std::invalid_argument for a bad pattern.
  void subscribe(std::string_view pattern, int qos = 0);

  State state() const { return state_; }
  const MqttOptions& options() const { return options_; }
  // Why the last attempt failed, a phrase ("Connection refused", "no answer within 10 s"); empty
  // before any failure and once connected.
  const std::string& lastFailure() const { return failure_; }

 private:
  static void handleConnect(mosquitto*, void* self, int rc);
  static void handleDisconnect(mosquitto*, void* self, int rc);
  static void handleMessage(mosquitto*, void* self, const mosquitto_message* message);
  static void handleLog(mosquitto*, void* self, int level, const char* text);
  static void handlePublish(mosquitto*, void* self, int mid);
  void settleDeliveries();  // calls the delivery waiters when nothing is unacknowledged

  void startAttempt(bool first);
  void attachSocket();
  void detachSocket();
  void service();  // runs read/write while the socket is ready, then re-arms the waits
  void arm();
  void failed(int rc);  // a loop call failed without the disconnect callback
  void scheduleMisc();
  // `why`: the phrase of lastFailure(); `reason` the sentence reported
  void lost(const std::string& reason, const std::string& why);
  void report(const std::string& reason, bool retrying);
  std::string where() const;
  std::string describe(int rc, int savedErrno) const;  // why a connection failed, a phrase

  Loop& loop_;
  MqttOptions options_;
  mosquitto* mosq_ = nullptr;
  boost::asio::posix::stream_descriptor fd_;
  State state_ = State::Idle;
  std::uint64_t generation_ = 0;  // bumped when the socket changes: stale waits are ignored
  bool readWaiting_ = false, writeWaiting_ = false;
  bool tcpPending_ = false;  // connect() in progress: wait for writability once
  bool inService_ = false;
  bool refused_ = false;       // the broker answered CONNACK with a refusal
  bool wasConnected_ = false;  // this attempt reached CONNACK
  Loop::TimerId miscTimer_ = 0, retryTimer_ = 0;
  Duration backoff_ = std::chrono::milliseconds(500);
  std::string lastReported_, lastLogError_;
  std::string failure_;
  std::map<std::string, int> subscriptions_;
  int batchDepth_ = 0;
  std::set<int> unacknowledged_;  // message ids of QoS 1/2 publications awaiting the broker
  struct DeliveryWaiter {
    std::function<void()> done;
    Loop::TimerId timer = 0;
  };
  std::vector<std::shared_ptr<DeliveryWaiter>> deliveryWaiters_;
  Loop::TimerId attemptTimer_ = 0;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

// One publication on a connection of its own, made and closed here, in at most `limit`; true
// once it is out (QoS 0) or the broker acknowledged it (QoS 1, 2). Blocking: for a thread other
// than the loop's (the watchdog's stop of a remote car, engine/core/emergency_stops.hpp).
bool publishOnce(const MqttOptions& options, const std::string& topic, const std::string& payload,
                 int qos, std::chrono::milliseconds limit);

}  // namespace pitwall
