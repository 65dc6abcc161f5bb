#pragma once
// The seed's MQTT topic tree (../shared/protocols/mqtt-topics.md, seed 000 §4.4) as pure
// functions: car messages and car/host life-cycle → publications, and (topic, payload) of an
// intent → a typed Intent or an error that says what is wrong. No sockets and no cars are touched
// here; the bridge publishes the results and executes valid intents. docs/mqtt-topics.md is the
// user-facing description of the same tree.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "engine/core/result.hpp"
#include "engine/protocol/anki/messages.hpp"
#include "engine/vehicles/anki_car.hpp"

namespace pitwall::topics {

// ---- hostile input (docs/mqtt.md "Hostile input") ----

// What a payload from the broker may be. Anyone who can publish on the broker can send anything:
// a larger payload is refused before it is parsed, a deeper one as soon as the parser reaches
// the limit, so a hostile publication costs little and cannot exhaust the stack.
inline constexpr std::size_t kDefaultMaxPayload = 64 * 1024;  // bytes; --mqtt-max-payload
inline constexpr int kMaxDepth = 64;  // nested objects and arrays; pitwall's own payloads use 1
struct PayloadLimits {
  std::size_t maxBytes = kDefaultMaxPayload;
  int maxDepth = kMaxDepth;
};

// How an error message shows text it received (a payload, a topic level, a value): at most
// `maxBytes` of it (then "…"), with every byte that is not part of a printable
// UTF-8 character (control characters, invalid UTF-8) as \xNN. The result is valid UTF-8 of at
// most 4 × maxBytes + 3 bytes.
std::string quote(std::string_view text, std::size_t maxBytes = 80);

struct Publication {
  std::string topic;
  std::string payload;  // JSON text
  int qos = 0;
  bool retain = false;
  bool operator==(const Publication&) const = default;
};

// Milliseconds since the epoch; passed in so that output is deterministic.
using Millis = std::int64_t;

// ---- identities ----

// The `<car>` of a topic from a link address. BLE ("ble:E8:5A:0F:11:22:33", or a bare address)
// gives the seed's (noble's) device id: the address in lowercase hex without separators
// ("e85a0f112233"). Any other link ("sim:0000002a") gives its address in lowercase with ':'
// replaced by '-' ("sim-0000002a"). Every character outside [a-z0-9._-] becomes '_', so the
// result never holds '/', '+' or '#'; "all" (reserved for every car) becomes "_all".
std::string carId(std::string_view linkAddress);
// A host id made topic-safe the same way (any character outside [A-Za-z0-9._-] becomes '_').
std::string hostId(std::string_view host);

// What S/Information carries (the car's advertisement).
struct CarInfo {
  std::string id;       // carId(address)
  std::string address;  // the link address without its "ble:" prefix
  std::uint32_t identifier = 0;
  std::uint8_t model_id = 0;
  std::uint16_t product_id = 0xBEEF;
  std::string name;  // the car's name in pitwall ("groundshock"); pitwall's extra key
  // pitwall's extra keys "bridge":"pitwall" and "host":"<host>": the car is bridged by a pitwall
  // bridge on that host, which publishes its every frame on E/frame and takes the message intent.
  // The seed's controller sends neither, so a remote reader knows a car's kind from its
  // S/Information, before any event arrives (docs/mqtt.md "Remote cars").
  bool pitwall = false;
  std::string host;  // with `pitwall`: the bridge's host id
};

// ---- car → broker ----

// Events (QoS 0, not retained) and status (QoS 1, retained) for one decoded vehicle message:
// the seed's events (E/speed, …), the seed's controller's whole-message events
// (E/Messages/ANKI_VEHICLE_MSG_V2C_…, see messageEventName) and its status topics.
// `pingRttSeconds` is AnkiCar::lastPingRtt() when `message` is a ping response. Messages with
// nothing in the tree (controller→vehicle ones, collisions, …) give no publication.
std::vector<Publication> fromMessage(std::string_view car, const anki::Message& message,
                                     std::optional<double> pingRttSeconds, Millis now);

// pitwall's extension: the vehicle's frame itself, Anki/Car/<car>/E/frame (QoS 0, not retained)
// {"timestamp":…,"value":"<hex>"}. It carries every message whole, so a remote pitwall turns it
// back into the same car events (docs/mqtt.md); tools of the seed ignore the extra topic.
Publication frameEvent(std::string_view car, std::span<const std::uint8_t> frame, Millis now);

// Status for a command that was sent to a car: S/Speed/Desired for a set-speed, S/Lane/Desired
// for a change-lane or set-offset; nothing for other commands.
std::vector<Publication> commandStatus(std::string_view car, const anki::Message& sent, Millis now);

// A car joined: S/Information, S/DiscoveryTime and S/CarStatus online (charging and onTrack
// from `state`).
std::vector<Publication> carJoined(const CarInfo& info, const CarState& state, Millis now);
// The seed's controller's host events when a car's connection comes up or goes down:
// Anki/Host/<host>/E/CarConnected and E/CarDisconnected {"timestamp":…,"Car":"<car>"}.
Publication carConnected(std::string_view host, std::string_view car, Millis now);
Publication carDisconnected(std::string_view host, std::string_view car, Millis now);
// A car (re)connected: S/CarStatus with online true.
Publication carOnline(std::string_view car, const CarState& state, Millis now);
// A car left: S/CarStatus with online false.
Publication carLeft(std::string_view car, const CarState& state, Millis now);

// Host status and events.
Publication hostOnline(std::string_view host);  // S/HostStatus {"value":true}
Publication hostWill(std::string_view host);    // the same topic with {"value":false}
// S/Cars: a bare JSON array of car ids, as the seed's controller publishes it and its clients
// iterate it (`[]` when there are none; the controller's `{}` makes a client's forEach throw).
Publication hostCars(std::string_view host, std::span<const std::string> cars);
Publication carDiscovered(std::string_view host, std::string_view car, Millis now);

// ---- broker → intents ----

// The topic filters a bridge subscribes to for intents.
std::vector<std::string> intentSubscriptions(std::string_view host);

struct Target {
  enum class Kind { Car, AllCars, Host };
  Kind kind = Kind::Car;
  std::string car;  // for Kind::Car
  bool operator==(const Target&) const = default;
};

// Host intents, on Anki/Host/<host>/I or any topic below it (the seed's controller matches both).
struct ConnectIntent {  // {"connecting":true|false}: scan and connect, or drop every car
  bool connecting = false;
  bool operator==(const ConnectIntent&) const = default;
};
struct CarsIntent {  // {"cars":true}: publish S/Cars again
  bool operator==(const CarsIntent&) const = default;
};
struct CarStatusIntent {  // {"car_status":true}: publish every car's S/Information again
  bool operator==(const CarStatusIntent&) const = default;
};
struct SpeedIntent {
  int speed_mm_s = 0;
  int accel_mm_s2 = 0;
  bool operator==(const SpeedIntent&) const = default;
};
struct LaneIntent {
  double offset_mm = 0;
  // pitwall's optional keys horizontalSpeed / horizontalAcceleration (AnkiCar::changeLane's
  // defaults when absent)
  std::optional<int> h_speed_mm_s, h_accel_mm_s2;
  bool operator==(const LaneIntent&) const = default;
};
struct TurnIntent {
  anki::TurnType type = anki::TurnType::None;
  anki::TurnTrigger trigger = anki::TurnTrigger::Immediate;
  bool operator==(const TurnIntent&) const = default;
};
struct BatteryIntent {
  bool operator==(const BatteryIntent&) const = default;
};
struct VersionIntent {
  bool operator==(const VersionIntent&) const = default;
};
struct PingIntent {
  bool operator==(const PingIntent&) const = default;
};

// pitwall's extension {"type":"message","frame":"<hex>"}: any controller→vehicle message as its
// frame (lights, set-offset, cancel lane change, …), decoded and range-checked like the others.
struct MessageIntent {
  anki::Message message;
  bool operator==(const MessageIntent&) const = default;
};

using Action = std::variant<ConnectIntent, CarsIntent, CarStatusIntent, SpeedIntent, LaneIntent,
                            TurnIntent, BatteryIntent, VersionIntent, PingIntent, MessageIntent>;

struct Intent {
  Target target;
  Action action;
  bool operator==(const Intent&) const = default;
};

struct IntentError {
  std::string topic;    // the intent's topic
  std::string message;  // one sentence: what is wrong, with the value and what is accepted
};

// Parses an intent received on `topic`. `knownCars` are the car ids a single-car intent may
// name. Values are checked against engine/protocol/anki/limits.hpp. A payload beyond `limits`,
// invalid UTF-8, or a number beyond a double is an error like any other; the error quotes at
// most 80 bytes of what was received (quote()).
Result<Intent, IntentError> parseIntent(std::string_view host, std::string_view topic,
                                        std::string_view payload,
                                        std::span<const std::string> knownCars,
                                        const PayloadLimits& limits = {});

// The answer to a rejected intent: Anki/Host/<host>/S/IntentError, QoS 1, not retained (an
// error belongs to one intent; a late subscriber must not see it as current state), payload
// {"timestamp":…,"topic":…,"error":…}. Whatever the error holds, the payload is valid JSON of
// at most kMaxIntentError bytes (a longer topic or sentence is cut, marked "…").
inline constexpr std::size_t kMaxIntentError = 1024;
Publication intentError(std::string_view host, const IntentError& error, Millis now);

// ---- the reading side: a remote pitwall's view of the tree ----

// The intent payload that asks a bridge to send `command` (a controller→vehicle message) to a car:
// the seed's controller's key-named form where one fits ({"speed":…,"acceleration":…},
// {"lane":…,"offset":…}, {"turn":{…}}, {"battery":true}, …), which a pitwall bridge and the
// seed's controller both execute; else pitwall's {"type":"message","frame":…}, which only a
// pitwall bridge executes. nullopt for a vehicle→controller message.
std::optional<std::string> intentPayload(const anki::Message& command);
// Only the controller's form: nullopt for a command the seed's controller has no intent for.
std::optional<std::string> controllerIntentPayload(const anki::Message& command);

// What a topic of the tree is about: Anki/Car/<car>/<rest> or Anki/Host/<host>/<rest>.
struct TopicParts {
  enum class Kind { Car, Host } kind = Kind::Car;
  std::string id;    // the car or the host
  std::string rest;  // "S/CarStatus", "E/frame", …
};
std::optional<TopicParts> splitTopic(std::string_view topic);

// Payload readers; an error says what is wrong with the payload (quoting at most 80 bytes of it,
// escaped). A payload beyond `limits` is refused before it is parsed.
Result<CarInfo, std::string> readInformation(std::string_view car, std::string_view payload,
                                             const PayloadLimits& limits = {});
struct CarOnline {
  bool online = false, charging = false, onTrack = false;
};
Result<CarOnline, std::string> readCarStatus(std::string_view payload,
                                             const PayloadLimits& limits = {});
Result<bool, std::string> readHostStatus(std::string_view payload,
                                         const PayloadLimits& limits = {});
// S/Cars: the bare array (the seed's controller's `{}` reads as none; the object
// {"timestamp":…,"value":[…]} of earlier pitwall bridges is read too).
Result<std::vector<std::string>, std::string> readHostCars(std::string_view payload,
                                                           const PayloadLimits& limits = {});
Result<std::vector<std::uint8_t>, std::string> readFrameEvent(std::string_view payload,
                                                              const PayloadLimits& limits = {});

// Anki/Car/<car>/E/Messages/<name>, the seed's controller's whole-message event for `message`
// (QoS 0, not retained); nullopt for a message the controller publishes none for.
std::optional<Publication> messageEvent(std::string_view car, const anki::Message& message,
                                        Millis now);
// The seed's controller's whole-message events: "ANKI_VEHICLE_MSG_V2C_LOCALIZATION_POSITION_UPDATE"
// for a position update, …; empty for a message without one.
std::string_view messageEventName(const anki::Message& message);
// E/Messages/<name> back into the vehicle message it was made from (a car of the seed's
// controller has no E/frame): the fields its payload carries, the rest zero. nullopt for a name
// without a message of its own (the payload is not read then); an error names the bad key.
Result<std::optional<anki::Message>, std::string> readMessageEvent(
    std::string_view name, std::string_view payload, const PayloadLimits& limits = {});

}  // namespace pitwall::topics
