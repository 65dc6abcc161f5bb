#include "engine/mqtt/bridge.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "engine/core/log.hpp"
#include "engine/core/overload.hpp"

namespace pitwall {

// Other hosts remembered from their S/Cars and S/HostStatus: more than any real tree holds.
constexpr std::size_t kMaxOtherHosts = 1024;

namespace {
constexpr const char* kLog = "mqtt bridge";
// The buckets of the host's own intents (car ids never hold a space): connecting, and the
// requests to publish the car list or the cars' information again, each of its own so that a
// flood of one never holds up the other.
const std::string kConnection = "connection";
const std::string kRepublish = "cars/car_status";

std::string perSecond(const RateLimit& r) {
  std::ostringstream out;
  out << r.perSecond << " a second, " << r.burst << " at once";
  return out.str();
}
}  // namespace

MqttBridge::MqttBridge(Loop& loop, Fleet& fleet, MqttClient& client, BridgeOptions options,
                       CarConnections connections)
    : loop_(loop),
      fleet_(fleet),
      client_(client),
      options_(std::move(options)),
      connections_(std::move(connections)),
      host_(topics::hostId(options_.host)) {
  const auto& w = client_.options().will;
  if (!w || w->topic != topics::hostWill(host_).topic)
    throw std::invalid_argument("the bridge's MQTT client needs MqttBridge::will(\"" + host_ +
                                "\") as its last will");
  client_.onConnected = [this] { connected(); };
  client_.onMessage = [this](std::string_view topic, std::string_view payload, bool retained) {
    message(topic, payload, retained);
  };
  if (!options_.readOnly) {
    for (const auto& filter : topics::intentSubscriptions(host_)) client_.subscribe(filter, 1);
    // Which cars the other bridges own, so that their single-car intents are left to them.
    client_.subscribe("Anki/Host/+/S/Cars", 1);
    client_.subscribe("Anki/Host/+/S/HostStatus", 1);
  }

  joinedSub_ = fleet_.carJoined.connect([this](AnkiCar& car) { joined(car); });
  connectionSub_ = fleet_.connectionChanged.connect(
      [this](AnkiCar& car, bool up, const std::string&) { connectionChanged(car, up); });
  framesSub_ = fleet_.frames.connect([this](AnkiCar& car, AnkiCar::Direction d,
                                            std::span<const std::uint8_t> f,
                                            const anki::Message& m) { frame(car, d, f, m); });
  // Cars that were connected before the bridge started.
  for (auto* car : fleet_.cars())
    if (car->state().connected) joined(*car);
  emit(topics::hostOnline(host_));
}

MqttBridge::~MqttBridge() {
  for (auto& [key, s] : dropped_) loop_.cancel(s.timer);
  loop_.cancel(unanswered_.timer);
  joinedSub_.disconnect();
  connectionSub_.disconnect();
  framesSub_.disconnect();
  client_.onConnected = nullptr;
  client_.onMessage = nullptr;
}

MqttWill MqttBridge::will(const std::string& host) {
  auto p = topics::hostWill(topics::hostId(host));
  return MqttWill{p.topic, p.payload, p.qos, p.retain};
}

topics::Millis MqttBridge::now() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

std::string MqttBridge::carIdOf(const AnkiCar& car) const {
  auto it = ids_.find(&car);
  if (it != ids_.end()) return it->second;
  // A simulated car's identifier is the same in every pitwall process (the grid numbers them
  // from a fixed base): the host id keeps the cars of two simulated bridges apart. A BLE
  // address is unique as it is.
  std::string address = const_cast<AnkiCar&>(car).link().address();
  std::string id = topics::carId(address);
  return address.starts_with("sim:") ? host_ + "-" + id : id;
}

void MqttBridge::emit(const topics::Publication& p) {
  if (offline_) return;  // a car's frame after the goodbye would contradict it
  if (p.retain) retained_[p.topic] = p;
  if (client_.publish(p.topic, p.payload, p.qos, p.retain))
    ++stats_.published;
  else
    ++stats_.dropped;
}

void MqttBridge::emit(const std::vector<topics::Publication>& ps) {
  for (const auto& p : ps) emit(p);
}

void MqttBridge::connected() {
  if (offline_) return;  // a reconnection after the goodbye says nothing
  // HostStatus true first (it replaces the will's false), then the rest of the retained state
  // as it was last published: the broker may have lost it (a restart without persistence).
  auto online = topics::hostOnline(host_);
  retained_[online.topic] = online;
  MqttClient::Batch batch(client_);
  auto send = [this](const topics::Publication& p) {
    if (client_.publish(p.topic, p.payload, p.qos, p.retain)) ++stats_.republished;
  };
  send(online);
  for (const auto& [topic, p] : retained_)
    if (topic != online.topic) send(p);
  for (const auto& p : undelivered_) emit(p);
  undelivered_.clear();
  log::info(kLog, "publishing as host " + host_ + (options_.readOnly ? " (read-only)" : ""));
}

std::vector<std::string> MqttBridge::ownCars() const {
  std::vector<std::string> out;
  for (const auto& [car, id] : ids_) out.push_back(id);
  std::sort(out.begin(), out.end());
  return out;
}

void MqttBridge::joined(AnkiCar& car) {
  if (ids_.count(&car)) return;
  std::string id = carIdOf(car);
  ids_[&car] = id;
  topics::CarInfo info;
  info.id = id;
  info.name = car.identity().name;
  info.pitwall = true;
  info.host = host_;
  info.address = car.link().address();
  if (info.address.starts_with("ble:")) info.address = info.address.substr(4);
  info.identifier = car.identity().identifier;
  info.model_id = car.identity().model_id;
  auto t = now();
  // An event, but the one a dashboard needs to learn of a car: one that happens before the first
  // connection to the broker waits for it (there is one per car at most).
  auto discovered = topics::carDiscovered(host_, id, t);
  if (client_.state() == MqttClient::State::Connected)
    emit(discovered);
  else
    undelivered_.push_back(std::move(discovered));
  emit(topics::carJoined(info, car.state(), t));
  if (car.state().connected) emit(topics::carConnected(host_, id, t));
  publishCars();
}

void MqttBridge::publishInformation() {
  for (const auto& [car, id] : ids_) {
    auto it = retained_.find("Anki/Car/" + id + "/S/Information");
    if (it != retained_.end()) emit(it->second);
  }
}

void MqttBridge::connectionChanged(AnkiCar& car, bool up) {
  auto it = ids_.find(&car);
  if (it == ids_.end()) return;  // not joined yet: joined() publishes it
  auto t = now();
  emit(up ? topics::carOnline(it->second, car.state(), t)
          : topics::carLeft(it->second, car.state(), t));
  // A car that comes back was found again, as the seed's controller's scan reports it.
  if (up) emit(topics::carDiscovered(host_, it->second, t));
  emit(up ? topics::carConnected(host_, it->second, t)
          : topics::carDisconnected(host_, it->second, t));
  publishCars();
}

void MqttBridge::publishCars(bool always) {
  std::vector<std::string> cars;
  for (const auto& [car, id] : ids_)
    if (car->state().connected) cars.push_back(id);
  std::sort(cars.begin(), cars.end());
  if (!always && haveCars_ && cars == lastCars_) return;
  haveCars_ = true;
  lastCars_ = cars;
  emit(topics::hostCars(host_, cars));
}

void MqttBridge::frame(AnkiCar& car, AnkiCar::Direction d, std::span<const std::uint8_t> bytes,
                       const anki::Message& m) {
  auto it = ids_.find(&car);
  if (it == ids_.end()) return;
  auto t = now();
  MqttClient::Batch batch(client_);  // one frame's publications, sent together
  if (d == AnkiCar::Direction::Tx) return emit(topics::commandStatus(it->second, m, t));
  emit(topics::frameEvent(it->second, bytes, t));
  std::optional<double> rtt;
  if (std::holds_alternative<anki::PingResponse>(m)) rtt = car.lastPingRtt();
  emit(topics::fromMessage(it->second, m, rtt, t));
}

bool MqttBridge::ownedElsewhere(const std::string& car) const {
  for (const auto& [host, cars] : otherCars_)
    if (host != host_ && otherOnline_.count(host) &&
        std::find(cars.begin(), cars.end(), car) != cars.end())
      return true;
  return false;
}

// The last resort: whatever a message from the broker makes throw (a parser, a serialiser, a
// command) is logged and the message dropped; the bridge and its cars carry on.
void MqttBridge::message(std::string_view topic, std::string_view payload, bool retained) {
  try {
    handle(topic, payload, retained);
  } catch (const std::exception& e) {
    ++stats_.faults;
    log::warn(kLog, "dropped the message on " + topics::quote(topic) + " (" +
                        std::to_string(payload.size()) +
                        " bytes): " + topics::quote(e.what(), 300));
  } catch (...) {
    ++stats_.faults;
    log::warn(kLog, "dropped the message on " + topics::quote(topic) + " (" +
                        std::to_string(payload.size()) + " bytes): an unknown exception");
  }
}

void MqttBridge::handle(std::string_view topic, std::string_view payload, bool retained) {
  if (options_.readOnly || offline_) return;
  auto parts = topics::splitTopic(topic);
  if (parts && parts->kind == topics::TopicParts::Kind::Host && parts->id != host_) {
    if (parts->rest == "S/Cars") {
      // At most kMaxOtherHosts remembered: ids a hostile publisher invents do not grow it.
      if (auto cars = topics::readHostCars(payload, options_.payload);
          cars && (otherCars_.count(parts->id) || otherCars_.size() < kMaxOtherHosts))
        otherCars_[parts->id] = *cars;
      return;
    }
    if (parts->rest == "S/HostStatus") {
      auto up = topics::readHostStatus(payload, options_.payload);
      if (up && *up && otherOnline_.size() < kMaxOtherHosts)
        otherOnline_.insert(parts->id);
      else
        otherOnline_.erase(parts->id);
      return;
    }
  }
  if (parts && parts->kind == topics::TopicParts::Kind::Host && parts->id == host_ &&
      parts->rest.starts_with("S/"))
    return;  // our own status, echoed back by the broker
  std::string t(topic);
  if (parts && parts->kind == topics::TopicParts::Kind::Car &&
      (parts->rest == "I" || parts->rest.starts_with("I/")) && parts->id != "all") {
    auto own = ownCars();
    if (!std::binary_search(own.begin(), own.end(), parts->id) && ownedElsewhere(parts->id))
      return;  // another bridge's car: its bridge answers
  }
  if (payload.empty()) return;  // how MQTT clears a retained message: nothing to execute
  if (retained)
    return reject(t,
                  "retained intents are not executed (a retained command would run again on "
                  "every reconnection); publish the intent without the retain flag, and clear the "
                  "stored one with an empty retained message");
  auto own = ownCars();
  auto intent = topics::parseIntent(host_, topic, payload, own, options_.payload);
  if (!intent) return reject(t, intent.error().message);
  execute(*intent, t);
}

void MqttBridge::reject(const std::string& topic, std::string message) {
  ++stats_.rejected;
  if (errorBucket_.take(options_.errors, loop_.now())) {
    log::warn(kLog, "intent on " + topics::quote(topic) + " rejected: " + message);
    emit(topics::intentError(host_, topics::IntentError{topic, std::move(message)}, now()));
  } else {
    // A flood of bad intents: one answer each would be a flood of errors (and of log lines).
    ++stats_.unanswered;
    ++unanswered_.count;
    unanswered_.topic = topic;
    unanswered_.last = std::move(message);
    summarise(unanswered_, [this](Summary& s) {
      std::string why = std::to_string(s.count) + " more intent" +
                        (s.count == 1 ? " was" : "s were") +
                        " rejected without an answer each (S/IntentError answers at most " +
                        perSecond(options_.errors) + "); the last: " + s.last;
      log::warn(kLog, why);
      emit(topics::intentError(host_, topics::IntentError{s.topic, why}, now()));
    });
  }
  if (onIntentHandled) onIntentHandled(topic, false);
}

bool MqttBridge::admit(const std::string& key, const std::string& topic) {
  if (intentBuckets_[key].take(options_.intents, loop_.now())) return true;
  ++stats_.throttled;
  auto& s = dropped_[key];
  ++s.count;
  s.topic = topic;
  summarise(s, [this, key](Summary& s) {
    const bool host = key == kConnection || key == kRepublish;
    std::string why = std::to_string(s.count) + " " +
                      (host ? key + " intent" + (s.count == 1 ? " was" : "s were") +
                                  " dropped: more than the host takes"
                            : std::string("intent") + (s.count == 1 ? "" : "s") + " for car " +
                                  key + (s.count == 1 ? " was" : " were") +
                                  " dropped: more than the car's link can take") +
                      " (at most " + perSecond(options_.intents) +
                      "); send fewer, e.g. only when a value changes";
    log::warn(kLog, why);
    emit(topics::intentError(host_, topics::IntentError{s.topic, why}, now()));
  });
  return false;
}

// The first of a quiet spell is reported at once; whatever follows within a second waits for
// one report at the end of that second.
void MqttBridge::summarise(Summary& s, std::function<void(Summary&)> report) {
  if (s.timer) return;  // a report is due already and will count this one too
  auto fire = [this, &s, report = std::move(report)] {
    s.timer = 0;
    s.reported = true;
    s.lastReport = loop_.now();
    report(s);
    s.count = 0;
  };
  auto due = s.lastReport + std::chrono::seconds(1);
  if (!s.reported || due <= loop_.now())
    fire();
  else
    s.timer = loop_.at(due, std::move(fire));
}

AnkiCar::Sent MqttBridge::apply(AnkiCar& car, const topics::Action& action) {
  using namespace topics;
  return std::visit(
      Overload{
          [&](const SpeedIntent& a) { return car.setSpeed(a.speed_mm_s, a.accel_mm_s2); },
          [&](const LaneIntent& a) {
            return car.changeLane(a.offset_mm, a.h_speed_mm_s.value_or(kDefaultLaneSpeed),
                                  a.h_accel_mm_s2.value_or(kDefaultLaneAccel));
          },
          [&](const TurnIntent& a) { return car.turn(a.type, a.trigger); },
          [&](const BatteryIntent&) { return car.requestBattery(); },
          [&](const VersionIntent&) { return car.requestVersion(); },
          [&](const PingIntent&) { return car.ping(); },
          [&](const MessageIntent& a) -> AnkiCar::Sent {
            if (std::holds_alternative<anki::Disconnect>(a.message)) return car.disconnect();
            if (auto* s = std::get_if<anki::SetSpeed>(&a.message))
              return car.setSpeed(s->speed_mm_s, s->accel_mm_s2, s->respect_limit);
            // Through the commands that keep the car's state in step (a remote car's setOffset
            // and cancelLaneChange arrive here), not the bare send().
            if (auto* o = std::get_if<anki::SetOffset>(&a.message))
              return car.setOffset(o->offset_mm);
            if (std::holds_alternative<anki::CancelLaneChange>(a.message))
              return car.cancelLaneChange();
            return car.send(a.message);
          },
          // host intents: execute() carries them out, they never reach a car
          [&](const ConnectIntent&) -> AnkiCar::Sent { return true; },
          [&](const CarsIntent&) -> AnkiCar::Sent { return true; },
          [&](const CarStatusIntent&) -> AnkiCar::Sent { return true; },
      },
      action);
}

namespace {
// A stop (speed 0) is never throttled: the rate limit must not stand between a car and its stop
// (docs/safety.md). A flood of stops costs the car nothing it would not do anyway.
bool isStop(const topics::Action& action) {
  if (auto* s = std::get_if<topics::SpeedIntent>(&action)) return s->speed_mm_s == 0;
  if (auto* m = std::get_if<topics::MessageIntent>(&action))
    if (auto* s = std::get_if<anki::SetSpeed>(&m->message)) return s->speed_mm_s == 0;
  return false;
}
}  // namespace

void MqttBridge::execute(const topics::Intent& intent, const std::string& topic) {
  using Kind = topics::Target::Kind;
  const bool stop = isStop(intent.action);
  if (auto* c = std::get_if<topics::ConnectIntent>(&intent.action)) {
    // Dropping every car is never throttled, as a stop is not (docs/safety.md): beyond the
    // rate it is still carried out, only not answered (no S/Cars unless the list changed, no
    // log line).
    bool answer = true;
    if (c->connecting) {
      if (!admit(kConnection, topic)) {
        if (onIntentHandled) onIntentHandled(topic, false);
        return;
      }
    } else {
      answer = intentBuckets_[kConnection].take(options_.intents, loop_.now());
    }
    ++stats_.intents;
    if (answer)
      log::info(kLog, c->connecting ? "connection intent: connecting the cars"
                                    : "connection intent: disconnecting every car");
    auto& f = c->connecting ? connections_.connectAll : connections_.disconnectAll;
    if (f) f();
    // The seed's controller answers a connection intent with S/Cars: its clients wait for that
    // publication (they skip a retained one), so it comes even when the list is unchanged; cars
    // that connect later publish it again.
    publishCars(answer);
    if (onIntentHandled) onIntentHandled(topic, true);
    return;
  }
  if (std::holds_alternative<topics::CarsIntent>(intent.action) ||
      std::holds_alternative<topics::CarStatusIntent>(intent.action)) {
    if (!admit(kRepublish, topic)) {
      if (onIntentHandled) onIntentHandled(topic, false);
      return;
    }
    ++stats_.intents;
    if (std::holds_alternative<topics::CarsIntent>(intent.action))
      publishCars(true);
    else
      publishInformation();
    if (onIntentHandled) onIntentHandled(topic, true);
    return;
  }
  if (intent.target.kind == Kind::Car) {
    for (auto& [car, id] : ids_) {
      if (id != intent.target.car) continue;
      if (!stop && !admit(id, topic)) {
        if (onIntentHandled) onIntentHandled(topic, false);
        return;
      }
      auto sent = apply(*const_cast<AnkiCar*>(car), intent.action);
      if (!sent) return reject(topic, sent.error());
      ++stats_.intents;
      if (onIntentHandled) onIntentHandled(topic, true);
      return;
    }
    return reject(topic, "unknown car \"" + intent.target.car + "\"");
  }
  // Every car of this host: those not connected are skipped (a drop is not the sender's error).
  for (auto& [car, id] : ids_) {
    if (!car->state().connected || (!stop && !admit(id, topic))) continue;
    auto sent = apply(*const_cast<AnkiCar*>(car), intent.action);
    if (!sent) log::warn(car->label(), "intent on " + topic + ": " + sent.error());
  }
  ++stats_.intents;
  if (onIntentHandled) onIntentHandled(topic, true);
}

void MqttBridge::goOffline() {
  auto t = now();
  for (const auto& [car, id] : ids_) emit(topics::carLeft(id, car->state(), t));
  lastCars_.clear();
  haveCars_ = true;
  emit(topics::hostCars(host_, {}));
  emit(topics::hostWill(host_));
  offline_ = true;
}

}  // namespace pitwall
