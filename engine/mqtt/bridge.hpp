#pragma once
// The MQTT bridge (docs/mqtt.md): the cars of a fleet published under the seed's topic tree
// (docs/mqtt-topics.md), and intents from any MQTT client executed on them.
//
//  - Every frame a car sends becomes its events and status (topics::fromMessage) plus pitwall's
//    E/frame; every command sent becomes S/Speed/Desired or S/Lane/Desired; joins and drops become
//    S/CarStatus, S/Cars, S/Information, S/DiscoveryTime, E/CarDiscovered, E/CarConnected and
//    E/CarDisconnected.
//  - Intents come in both forms: the seed's controller's (the key names the command, on its
//    topics Anki/Host/<host>/I/#, Anki/Car/+/I/#, Anki/Car/I) and pitwall's "type" forms.
//  - Retained status is kept in a cache and republished whole after every (re)connection to the
//    broker, HostStatus true first; events that happen while the broker is away are dropped, not
//    queued, so a reconnection brings no flood of stale events.
//  - Intents are parsed by topics::parseIntent; a rejected one is answered on
//    Anki/Host/<host>/S/IntentError and nothing is sent to any car. A single-car intent for a car
//    that another online bridge lists in its S/Cars is left to that bridge, silently.
//  - read-only: intents are not even subscribed to.
//  - Hostile input is contained (docs/mqtt.md "Hostile input"): an intent beyond
//    BridgeOptions::payload is refused before it is parsed; each car takes at most
//    BridgeOptions::intents (a token bucket), the rest is dropped and summed up on S/IntentError
//    at most once a second per car; S/IntentError itself carries at most BridgeOptions::errors,
//    the rest summed up once a second; an exception from any message is caught, logged, and the
//    message dropped.
#include <chrono>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "engine/core/token_bucket.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/mqtt/topics.hpp"
#include "engine/transport/mqtt_client.hpp"

namespace pitwall {

struct BridgeOptions {
  std::string host;  // the host id (topics::hostId applied by the bridge)
  bool readOnly = false;
  topics::PayloadLimits payload{};  // an intent larger or deeper is refused before it is parsed
  // Intents per car (and connection intents per host): a BLE link takes about 20–50 commands a
  // second, so 50 a second, 20 at once; the rest are dropped, not queued.
  RateLimit intents{50, 20};
  RateLimit errors{10, 20};  // S/IntentError answers, one per rejected intent
};

// How the bridge carries out a connection intent: scan and connect every car, or drop them all.
struct CarConnections {
  std::function<void()> connectAll;
  std::function<void()> disconnectAll;
};

class MqttBridge {
 public:
  // The client must not be connected yet: the bridge sets its will and handlers. The fleet, the
  // client and the loop outlive the bridge.
  MqttBridge(Loop& loop, Fleet& fleet, MqttClient& client, BridgeOptions options,
             CarConnections connections);
  ~MqttBridge();
  MqttBridge(const MqttBridge&) = delete;
  MqttBridge& operator=(const MqttBridge&) = delete;

  // The will a bridge's client must carry (HostStatus false, retained, QoS 1).
  static MqttWill will(const std::string& host);

  // Before a clean shutdown: every car offline, S/Cars empty, HostStatus false (the will is not
  // sent on a clean DISCONNECT). The last word: nothing is published or executed after it.
  void goOffline();

  const std::string& host() const { return host_; }
  // The car's <car> in the tree: topics::carId of its address; for a simulated car prefixed with
  // the host id ("pit1-sim-51a00001").
  std::string carIdOf(const AnkiCar& car) const;

  struct Stats {
    std::uint64_t published = 0;    // publications handed to the client
    std::uint64_t dropped = 0;      // not connected to the broker: dropped, not queued
    std::uint64_t intents = 0;      // intents executed
    std::uint64_t rejected = 0;     // intents refused (answered on S/IntentError, or summed up)
    std::uint64_t throttled = 0;    // intents for a car beyond BridgeOptions::intents: dropped
    std::uint64_t unanswered = 0;   // refusals beyond BridgeOptions::errors: only summed up
    std::uint64_t faults = 0;       // messages that threw: logged and dropped
    std::uint64_t republished = 0;  // retained status sent again after a (re)connection
  };
  const Stats& stats() const { return stats_; }

  // Called after an intent was handled (executed or rejected), for tests and logs.
  std::function<void(const std::string& topic, bool executed)> onIntentHandled;

 private:
  static topics::Millis now();
  void emit(const topics::Publication& p);
  void emit(const std::vector<topics::Publication>& ps);
  void connected();
  void joined(AnkiCar& car);
  void connectionChanged(AnkiCar& car, bool up);
  // S/Cars when the list changed, or `always` (the answer to a connection or cars intent).
  void publishCars(bool always = false);
  // Every car's S/Information again (a car_status intent).
  void publishInformation();
  void frame(AnkiCar& car, AnkiCar::Direction d, std::span<const std::uint8_t> bytes,
             const anki::Message& m);
  void message(std::string_view topic, std::string_view payload, bool retained);
  void handle(std::string_view topic, std::string_view payload, bool retained);
  bool ownedElsewhere(const std::string& car) const;
  void execute(const topics::Intent& intent, const std::string& topic);
  AnkiCar::Sent apply(AnkiCar& car, const topics::Action& action);
  void reject(const std::string& topic, std::string message);
  // One token of `key`'s bucket (a car id, or kConnection); false, counted and later summed up
  // on S/IntentError, when there is none.
  bool admit(const std::string& key, const std::string& topic);
  // What was held back (intents dropped, errors not published), summed up at most once a second.
  struct Summary {
    std::uint64_t count = 0;
    std::string topic, last;  // the last one's topic and error
    TimePoint lastReport{};
    bool reported = false;
    Loop::TimerId timer = 0;
  };
  void summarise(Summary& s, std::function<void(Summary&)> report);
  std::vector<std::string> ownCars() const;

  Loop& loop_;
  Fleet& fleet_;
  MqttClient& client_;
  BridgeOptions options_;
  CarConnections connections_;
  std::string host_;
  std::map<const AnkiCar*, std::string> ids_;            // cars that joined, by their topic id
  std::map<std::string, topics::Publication> retained_;  // last retained publication per topic
  std::vector<std::string> lastCars_;
  std::vector<topics::Publication> undelivered_;  // CarDiscovered before the first connection
  bool haveCars_ = false;
  bool offline_ = false;  // goOffline() said the last word
  // What the other bridges said: their cars, while they are online.
  std::map<std::string, std::vector<std::string>> otherCars_;
  std::set<std::string> otherOnline_;
  std::map<std::string, TokenBucket> intentBuckets_;  // by car id, and kConnection
  std::map<std::string, Summary> dropped_;            // the same keys
  TokenBucket errorBucket_;
  Summary unanswered_;
  Stats stats_;
  // The fleet's events, while the bridge lives (after whoever subscribed before it).
  Subscription joinedSub_, connectionSub_, framesSub_;
};

}  // namespace pitwall
