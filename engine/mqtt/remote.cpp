#include "engine/mqtt/remote.hpp"

#include <unistd.h>

#include <random>

#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/protocol/anki/codec.hpp"

namespace pitwall {

namespace {
constexpr const char* kLog = "mqtt remote";
constexpr RateLimit kWarnings{10, 20};
}  // namespace

// A remote car's link: frames arrive from the broker, commands leave as intents.
class RemoteLink : public Link {
 public:
  RemoteLink(RemoteCars& owner, std::string id) : owner_(owner), id_(std::move(id)) {}
  ~RemoteLink() override { emergency::removeStopper(std::exchange(stopper_, 0)); }

  bool send(std::span<const std::uint8_t> frame) override {
    refusal_.clear();
    if (!up_) return false;
    if (auto why = owner_.sendCommand(id_, frame)) {
      refusal_ = std::move(*why);
      return false;
    }
    return true;
  }
  std::string refusal() const override { return refusal_; }
  bool connected() const override { return up_; }
  // A remote car is the other bridge's to drop: AnkiCar::disconnect() has already sent the
  // disconnect message as an intent, and the car's status follows from its bridge.
  void disconnect() override {}
  std::string address() const override { return "mqtt:" + id_; }
  // The stop outside the loop: the car's intent, published by the watchdog's thread on a
  // connection of its own while the car is online.
  void setEmergencyStop(std::span<const std::uint8_t> frame) override {
    stop_.assign(frame.begin(), frame.end());
    registerEmergency();
  }

  void set(bool up, const std::string& reason) {
    if (up == up_) return;
    up_ = up;
    registerEmergency();
    deliverState(up, reason);
  }
  void frame(std::span<const std::uint8_t> bytes) {
    if (up_) deliverFrame(bytes);
  }

 private:
  RemoteCars& owner_;
  std::string id_;
  void registerEmergency() {
    emergency::removeStopper(std::exchange(stopper_, 0));
    if (up_ && !stop_.empty())
      if (auto stopper = owner_.emergencyStopper(id_, stop_))
        stopper_ = emergency::addStopper(stopper);
  }

  bool up_ = false;
  std::string refusal_;  // why the last send() was refused
  std::vector<std::uint8_t> stop_;
  int stopper_ = 0;
};

RemoteCars::RemoteCars(Loop& loop, Fleet& fleet, MqttClient& client, topics::PayloadLimits limits)
    : loop_(loop), fleet_(fleet), client_(client), limits_(limits) {
  std::random_device random;
  syncTopic_ = "pitwall/sync/" + std::to_string(::getpid()) + "-" + std::to_string(random());
  client_.subscribe("Anki/Host/+/S/#", 1);
  client_.subscribe("Anki/Car/+/S/#", 1);
  client_.subscribe("Anki/Car/+/E/frame", 0);
  // A car of the seed's controller has no E/frame: its whole-message events stand in for it.
  client_.subscribe("Anki/Car/+/E/Messages/#", 0);
  client_.subscribe(syncTopic_, 1);
  client_.onConnected = [this] {
    brokerUp_ = true;
    if (readOnly_) {  // a spectator publishes nothing: the retained state comes as it comes
      if (auto done = std::move(synced_)) {
        synced_ = nullptr;
        done();
      }
      return;
    }
    // After the retained state of the subscriptions above (same client, same QoS: in order).
    client_.publish(syncTopic_, "{}", 1, false);
  };
  client_.onDisconnected = [this](const std::string& reason, bool retrying) {
    brokerUp_ = false;  // the client has logged why
    for (auto& [id, car] : cars_)
      if (car.link) car.link->set(false, "MQTT: " + reason);
    if (onChange) onChange();
    if (!retrying && failed_) failed_(reason);
  };
  client_.onMessage = [this](std::string_view topic, std::string_view payload, bool) {
    message(topic, payload);
  };
}

RemoteCars::~RemoteCars() {
  client_.onConnected = nullptr;
  client_.onDisconnected = nullptr;
  client_.onMessage = nullptr;
}

void RemoteCars::start(std::function<void()> synced,
                       std::function<void(const std::string&)> failed) {
  synced_ = std::move(synced);
  failed_ = std::move(failed);
  client_.connect();
}

std::size_t RemoteCars::onlineCount() const {
  std::size_t n = 0;
  for (const auto& [id, car] : cars_) n += car.link && car.link->connected() ? 1 : 0;
  return n;
}

bool RemoteCars::hostUp(const std::string& host) const {
  auto it = hosts_.find(host);
  return host.empty() || it == hosts_.end() || it->second;
}

namespace {
// Bounds against a publisher that invents ids: more than any real tree holds.
constexpr std::size_t kMaxTracked = 1024;    // car ids and host ids remembered
constexpr std::size_t kMaxRemoteCars = 256;  // remote cars in the fleet
constexpr std::size_t kMaxName = 64;         // bytes of a remote car's name
}  // namespace

RemoteCars::Car* RemoteCars::track(const std::string& id, std::string_view topic) {
  if (auto it = cars_.find(id); it != cars_.end()) return &it->second;
  if (cars_.size() >= kMaxTracked) {
    warn("ignored " + topics::quote(topic) + ": the tree names more than " +
         std::to_string(kMaxTracked) + " cars; no more are followed");
    return nullptr;
  }
  return &cars_[id];
}

std::size_t RemoteCars::linkedCount() const {
  std::size_t n = 0;
  for (const auto& [id, car] : cars_) n += car.link != nullptr;
  return n;
}

void RemoteCars::warn(const std::string& line) {
  if (!warnings_.take(kWarnings, loop_.now())) {
    ++unlogged_;
    return;
  }
  std::string more;
  if (unlogged_)
    more = " (" + std::to_string(unlogged_) + " more warning" + (unlogged_ == 1 ? "" : "s") +
           " not logged before this one: more than 10 a second)";
  unlogged_ = 0;
  log::warn(kLog, line + more);
}

// The last resort: whatever a publication makes throw is logged and the publication dropped.
void RemoteCars::message(std::string_view topic, std::string_view payload) {
  try {
    handle(topic, payload);
  } catch (const std::exception& e) {
    warn("dropped the message on " + topics::quote(topic) + " (" + std::to_string(payload.size()) +
         " bytes): " + topics::quote(e.what(), 300));
  } catch (...) {
    warn("dropped the message on " + topics::quote(topic) + " (" + std::to_string(payload.size()) +
         " bytes): an unknown exception");
  }
}

void RemoteCars::handle(std::string_view topic, std::string_view payload) {
  if (topic == syncTopic_) {
    if (auto done = std::move(synced_)) {
      synced_ = nullptr;
      done();
    }
    return;
  }
  auto parts = topics::splitTopic(topic);
  if (!parts) return;
  auto complain = [&](const std::string& why) {
    warn("ignored " + topics::quote(topic) + ": " + why);
  };
  if (parts->kind == topics::TopicParts::Kind::Host) {
    if (parts->rest == "S/HostStatus") {
      auto up = topics::readHostStatus(payload, limits_);
      if (!up) return complain(up.error());
      if (!hosts_.count(parts->id) && hosts_.size() >= kMaxTracked)
        return complain("the tree names more than " + std::to_string(kMaxTracked) +
                        " hosts; no more are followed");
      hosts_[parts->id] = *up;
      for (auto& [id, car] : cars_)
        if (car.host == parts->id) update(id, car);
    } else if (parts->rest == "S/Cars") {
      auto list = topics::readHostCars(payload, limits_);
      if (!list) return complain(list.error());
      std::set<std::string> named;
      for (const auto& id : *list)
        if (Car* car = track(id, topic)) {
          car->host = parts->id;
          car->listed = car->everListed = true;
          named.insert(id);
        }
      for (auto& [id, car] : cars_) {
        if (car.host != parts->id) continue;
        if (!named.count(id)) car.listed = false;
        update(id, car);
      }
    } else if (parts->rest == "S/IntentError") {
      // Only errors about intents we might have sent: single-car intents to remote cars.
      for (const auto& [id, car] : cars_)
        if (car.link && payload.find("\"Anki/Car/" + id + "/I\"") != std::string_view::npos)
          warn("host " + topics::quote(parts->id) +
               " refused an intent: " + topics::quote(payload, topics::kMaxIntentError));
    }
    return;
  }
  const std::string& id = parts->id;
  if (parts->rest == "E/frame") {
    auto it = cars_.find(id);
    // Only a pitwall bridge's car reads E/frame (its S/Information says so); a frame for any
    // other comes from no bridge of its own.
    if (it == cars_.end() || !it->second.link || !it->second.pitwall()) return;
    auto bytes = topics::readFrameEvent(payload, limits_);
    if (!bytes) return complain(bytes.error());
    it->second.link->frame(*bytes);
  } else if (parts->rest.starts_with("E/Messages/")) {
    auto it = cars_.find(id);
    // Only a car of the seed's controller reads them: a pitwall bridge publishes them too, but
    // its E/frame carries every message already.
    if (it == cars_.end() || !it->second.link || !it->second.link->connected() ||
        !it->second.seed())
      return;
    auto message =
        topics::readMessageEvent(std::string_view(parts->rest).substr(11), payload, limits_);
    if (!message) return complain(message.error());
    if (!*message) return;  // a message without a counterpart here
    auto frame = anki::encode(**message);
    it->second.link->frame(frame.span());
  } else if (parts->rest == "S/Information") {
    auto info = topics::readInformation(id, payload, limits_);
    if (!info) return complain(info.error());
    Car* car = track(id, topic);
    if (!car) return;
    if (info->address.empty())
      car->info.reset();  // the seed's controller blanks it when it drops the car
    else
      car->info = *info;
    update(id, *car);
  } else if (parts->rest == "S/CarStatus") {
    auto status = topics::readCarStatus(payload, limits_);
    if (!status) return complain(status.error());
    Car* car = track(id, topic);
    if (!car) return;
    car->online = status->online;
    update(id, *car);
  }
}

std::string RemoteCars::uniqueName(const topics::CarInfo& info) const {
  std::vector<std::string> taken;
  for (const auto* c : fleet_.cars()) taken.push_back(c->identity().name);
  if (info.name.empty()) return anki::uniqueCarName(info.model_id, taken);
  std::size_t cut = std::min(info.name.size(), kMaxName);
  while (cut > 0 && cut < info.name.size() && (info.name[cut] & 0xC0) == 0x80) --cut;  // UTF-8
  std::string name = info.name.substr(0, cut);
  const std::string base = name;
  for (int n = 2; std::find(taken.begin(), taken.end(), name) != taken.end(); ++n)
    name = base + std::to_string(n);
  return name;
}

bool RemoteCars::Car::present() const {
  // A host's S/Cars, once it named the car, decides (the seed's controller publishes no
  // S/CarStatus when it drops a car, and the one left retained may say either); a car no
  // S/Cars named yet is as its S/CarStatus says.
  if (everListed) return listed;
  return online.value_or(false);
}

void RemoteCars::update(const std::string& id, Car& car) {
  bool up = brokerUp_ && car.present() && car.info && car.infoCurrent() && hostUp(car.host);
  if (!car.link) {
    if (!up) return;
    if (linkedCount() >= kMaxRemoteCars)
      return warn("remote car " + topics::quote(id) + " not taken: already " +
                  std::to_string(kMaxRemoteCars) + " remote cars");
    auto link = std::make_unique<RemoteLink>(*this, id);
    car.link = link.get();
    CarIdentity identity;
    identity.name = uniqueName(*car.info);
    identity.model_id = car.info->model_id;
    identity.identifier = car.info->identifier;
    auto& added = fleet_.add(std::move(link), std::move(identity));
    log::info(kLog, added.label() + " is " + id + (car.host.empty() ? "" : " on host " + car.host));
  }
  std::string reason = !car.present() ? "its bridge reports it offline"
                       : !car.info    ? "its bridge has no information on it"
                       : !car.infoCurrent()
                           ? "host " + car.host + " has it, but its information is host " +
                                 car.info->host + "'s (waiting for " + car.host + "'s)"
                       : !hostUp(car.host) ? "host " + car.host + " is offline"
                       : !brokerUp_        ? "lost the MQTT broker"
                                           : "connected through the MQTT broker";
  bool was = car.link->connected();
  car.link->set(up, reason);
  if (was != up && onChange) onChange();
}

std::optional<std::string> RemoteCars::sendCommand(const std::string& car,
                                                   std::span<const std::uint8_t> frame) {
  if (readOnly_) return "a spectator sends no commands";
  auto message = anki::decode(frame);
  if (!message) return message.error().message();
  if (std::holds_alternative<anki::SdkMode>(*message)) return std::nullopt;
  auto it = cars_.find(car);
  if (it != cars_.end() && it->second.seed() && !topics::controllerIntentPayload(*message)) {
    // Its bridge would drop it without a word: refuse it here, saying why.
    return "car " + car +
           " is bridged by the seed's controller (its S/Information names no pitwall bridge), " +
           "which has no intent for " + std::string(anki::name(*message)) +
           "; it takes speed, lane, turn, battery, version and ping";
  }
  auto payload = topics::intentPayload(*message);
  if (!payload) return std::string(anki::name(*message)) + " is not a command";
  if (!client_.publish("Anki/Car/" + car + "/I", *payload, 1, false))
    return "not connected to the MQTT broker";
  return std::nullopt;
}

emergency::Stopper RemoteCars::emergencyStopper(const std::string& car,
                                                std::span<const std::uint8_t> frame) const {
  if (readOnly_) return nullptr;
  auto message = anki::decode(frame);
  if (!message) return nullptr;
  auto payload = topics::intentPayload(*message);
  if (!payload) return nullptr;
  return [options = client_.options(), topic = "Anki/Car/" + car + "/I", payload = *payload] {
    return publishOnce(options, topic, payload, 1, std::chrono::milliseconds(800));
  };
}

}  // namespace pitwall
