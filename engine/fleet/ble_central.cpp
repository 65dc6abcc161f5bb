#include "engine/fleet/ble_central.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>

#include "engine/core/log.hpp"
#include "engine/fleet/connection_interval.hpp"
#include "engine/protocol/anki/advertisement.hpp"

namespace pitwall::ble {

namespace {

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
  return s;
}

std::string lastName(const std::string& path) {
  return path.substr(path.rfind('/') + 1);
}

std::string names(const std::vector<const Adapter*>& adapters) {
  std::string out;
  for (const auto* a : adapters) out += (out.empty() ? "" : ", ") + a->name;
  return out;
}

std::string secondsText(Duration d) {
  std::ostringstream s;
  s << toSeconds(d) << " s";
  return s.str();
}

}  // namespace

void scanForCars(Bluez& bluez, const std::vector<const Adapter*>& adapters, Duration duration,
                 const std::vector<std::string>& wanted,
                 std::function<void(std::optional<std::string>, std::vector<Sighting>)> done) {
  struct State {
    std::map<std::string, Sighting> seen;  // by address
    std::set<std::string> adapterPaths, wanted;
    std::function<void(const Device&)> previous;
    Loop::TimerId timer = 0;
    int starting = 0;
    bool finished = false;
    std::optional<std::string> error;
    std::function<void()> finish;
  };
  auto state = std::make_shared<State>();
  for (const auto* a : adapters) state->adapterPaths.insert(a->path);
  for (const auto& w : wanted) state->wanted.insert(upper(w));
  state->previous = bluez.onDevice;

  auto record = [state](const Device& d) {
    if (!d.isAnki() || !state->adapterPaths.count(d.adapter)) return false;
    std::string address = upper(d.address);
    if (!state->wanted.empty() && !state->wanted.count(address)) return false;
    auto& s = state->seen[address];
    s.address = address;
    s.paths[d.adapter] = d.path;
    s.device = d;
    return true;
  };
  auto allWantedSeen = [state] {
    if (state->wanted.empty()) return false;
    return std::all_of(state->wanted.begin(), state->wanted.end(),
                       [&](const std::string& w) { return state->seen.count(w) > 0; });
  };

  // A weak reference: the state owns `finish`, so a strong one would keep the state alive
  // forever (found by LeakSanitizer, docs/testing.md). Whoever calls finish holds the state.
  state->finish = [&bluez, weak = std::weak_ptr<State>(state), done] {
    auto state = weak.lock();
    if (!state || state->finished) return;
    state->finished = true;
    bluez.loop().cancel(state->timer);
    bluez.onDevice = state->previous;
    for (const auto& path : state->adapterPaths) bluez.stopDiscovery(path);
    std::vector<Sighting> out;
    for (auto& [address, s] : state->seen) out.push_back(std::move(s));
    auto error = state->error;
    // Not from inside a D-Bus callback of ours: the caller may tear things down.
    bluez.loop().post(
        [done, error, out = std::move(out)]() mutable { done(error, std::move(out)); });
  };

  // Cars already connected to this host, and cars asked for by address that BlueZ knows from an
  // earlier scan, count as seen: BlueZ can connect to them without a fresh advertisement.
  for (const auto& [path, d] : bluez.devices())
    if (d.connected || state->wanted.count(upper(d.address))) record(d);

  bluez.onDevice = [state, record, allWantedSeen](const Device& d) {
    if (state->previous) state->previous(d);
    if (state->finished) return;
    if (record(d) && allWantedSeen()) state->finish();
  };
  if (allWantedSeen()) return state->finish();

  state->timer = bluez.loop().after(duration, [state] {
    state->timer = 0;
    state->finish();
  });
  for (const auto* a : adapters) {
    ++state->starting;
    bluez.startDiscovery(a->path, [state](std::optional<std::string> error) {
      --state->starting;
      if (error && !state->error) {
        state->error = error;
        state->finish();
      }
    });
  }
}

struct Central::Car {
  std::string address, adapter;
  BleLink* link = nullptr;
  AnkiCar* car = nullptr;
  int failures = 0, attempts = 0;
  Loop::TimerId retry = 0;
  bool firstAttemptDone = false;
  bool vanished = false;
};

Central::Central(Loop& loop, Fleet& fleet, CentralOptions options)
    : loop_(loop),
      fleet_(fleet),
      options_(std::move(options)),
      bluez_(std::make_unique<Bluez>(loop)),
      alive_(std::make_shared<bool>(true)) {
  bluez_->onDevice = [this](const Device& d) { deviceSeen(d); };
  bluez_->onDeviceRemoved = [this](const std::string& path) {
    for (auto& c : cars_)
      if (c->link->devicePath() == path && !c->vanished) {
        c->link->deviceRemoved();
        vanished(*c);
      }
  };
  // bluetoothd restarted: its devices went away with it (each car is looking for its own);
  // look again on the adapters that have cars to find.
  bluez_->onBluezBack = [this] {
    for (auto& [path, q] : queues_)
      if (q.discoverers > 0 && !shuttingDown_)
        bluez_->startDiscovery(path, [](std::optional<std::string> error) {
          if (error) log::warn("ble", *error);
        });
  };
  // a controller unplugged and plugged back (or powered off and on): its cars that vanished with
  // it are looked for on it again
  bluez_->onAdapterReady = [this](const std::string& path) {
    auto it = queues_.find(path);
    if (it == queues_.end() || it->second.discoverers == 0 || shuttingDown_) return;
    log::info("ble", path.substr(path.rfind('/') + 1) + " is back: looking for its cars");
    bluez_->startDiscovery(path, [](std::optional<std::string> error) {
      if (error) log::warn("ble", *error);
    });
  };
  bluez_->onValue = [this](const std::string& charPath, const std::vector<std::uint8_t>& v) {
    for (auto& c : cars_)
      if (c->link->notifyPath() == charPath) return c->link->value(v);
  };
}

Central::~Central() {
  *alive_ = false;
  for (auto& c : cars_) loop_.cancel(c->retry);
}

std::map<std::string, int> Central::attempts() const {
  std::map<std::string, int> out;
  for (const auto& c : cars_) out[c->address] = c->attempts;
  return out;
}

void Central::start(std::function<void(std::optional<std::string> error)> done) {
  std::weak_ptr<bool> alive = alive_;
  bluez_->start([this, alive, done](std::optional<std::string> error) {
    if (alive.expired()) return;
    if (error) return done(error);
    std::vector<const Adapter*> adapters;
    try {
      adapters = bluez_->pickAdapters(options_.adapters);
    } catch (const BleError& e) {
      return done(std::string(e.what()));
    }
    for (const auto* a : adapters) queues_[a->path];
    // Other devices connected through a racing adapter (a phone, a gamepad) share its airtime
    for (const auto& [path, d] : bluez_->devices()) {
      if (!d.connected || d.isAnki() || !queues_.count(d.adapter)) continue;
      log::warn("ble", lastName(d.adapter) + " also holds " +
                           (d.name.empty() ? d.address : d.name + " (" + d.address + ")") +
                           ", which is not a car: it shares the controller's airtime with the "
                           "cars; give it another adapter, or give the cars their own (--adapter)");
    }
    log::info("ble", "looking for Anki cars on " + names(adapters) + " for up to " +
                         secondsText(options_.scan));
    std::string where = names(adapters);
    scanForCars(
        *bluez_, adapters, options_.scan, options_.cars,
        [this, alive, done, where](std::optional<std::string> error, std::vector<Sighting> found) {
          if (alive.expired()) return;
          if (error) return done(error);
          for (const auto& w : options_.cars)
            if (std::none_of(found.begin(), found.end(),
                             [&](const Sighting& s) { return s.address == upper(w); }))
              log::warn("ble", "car " + upper(w) + " was not found on " + where);
          if (found.empty())
            return done("no Anki car found on " + where + " in " + secondsText(options_.scan) +
                        ": are the cars switched on (lights blinking), charged, and not "
                        "connected to a phone or another host?");
          firstRoundDone_ = done;
          addCars(found);
        });
  });
}

void Central::addCars(const std::vector<Sighting>& sightings) {
  std::map<std::string, int> load;
  for (const auto& c : cars_) ++load[c->adapter];
  std::vector<std::string> taken;
  for (const auto* c : fleet_.cars()) taken.push_back(c->identity().name);
  for (const auto& s : sightings) {
    // The least loaded adapter that saw the car, among those with room for it
    std::string adapter, path;
    for (const auto& [a, p] : s.paths)
      if (load[a] < options_.carsPerAdapter && (adapter.empty() || load[a] < load[adapter]))
        adapter = a, path = p;
    if (adapter.empty()) {
      std::string full;
      for (const auto& [a, p] : s.paths) full += (full.empty() ? "" : ", ") + lastName(a);
      log::warn("ble", "the car at " + s.address + " is left out: " + full +
                           (s.paths.size() > 1 ? " hold " : " holds ") +
                           std::to_string(options_.carsPerAdapter) +
                           " cars already (--cars-per-adapter " +
                           std::to_string(options_.carsPerAdapter) +
                           "); plug in another adapter and name it with --adapter, or raise "
                           "--cars-per-adapter if the controller holds more (docs/bluetooth.md)");
      continue;
    }
    ++load[adapter];
    auto car = std::make_unique<Car>();
    car->address = s.address;
    car->adapter = adapter;
    auto link = std::make_unique<BleLink>(*bluez_, path, s.address, options_.timeouts);
    car->link = link.get();
    Car* raw = car.get();
    link->onDropped = [this, raw](const std::string& why) { retryLater(*raw, why); };
    CarIdentity identity;
    if (s.device.manufacturer) {
      identity.model_id = s.device.manufacturer->model_id;
      identity.identifier = s.device.manufacturer->identifier;
    }
    // The user name where BlueZ let us read it, else the model's name, made unique as the
    // simulator does (groundshock, groundshock2, …).
    identity.name = s.device.localName().user_name;
    if (identity.name.empty() && s.device.manufacturer)
      identity.name = anki::uniqueCarName(identity.model_id, taken);
    taken.push_back(identity.name);
    car->car = &fleet_.add(std::move(link), std::move(identity));
    log::info("ble", "found " + car->car->label() + " at " + s.address + " on " +
                         adapter.substr(adapter.rfind('/') + 1));
    cars_.push_back(std::move(car));
  }
  // What BlueZ asks each connection for, and whether that suits the cars an adapter now holds
  const LeInterval interval = leInterval(options_.bluezConfig);
  for (const auto& [adapter, n] : load) {
    if (n == 0 || intervalTold_[adapter] == n) continue;
    intervalTold_[adapter] = n;
    bool suits = true;
    std::string sentence = intervalSentence(lastName(adapter), n, interval, suits);
    if (suits)
      log::info("ble", sentence);
    else
      log::warn("ble", sentence);
  }
  for (auto& c : cars_) enqueue(*c);
}

void Central::enqueue(Car& car) {
  if (shuttingDown_ || car.vanished || car.car->state().connected) return;
  auto& q = queues_[car.adapter];
  if (q.busy == &car || std::find(q.waiting.begin(), q.waiting.end(), &car) != q.waiting.end())
    return;
  q.waiting.push_back(&car);
  pump(q);
}

void Central::pump(AdapterQueue& q) {
  if (q.busy || q.waiting.empty() || shuttingDown_) return;
  Car* car = q.waiting.front();
  q.waiting.pop_front();
  q.busy = car;
  ++car->attempts;
  std::weak_ptr<bool> alive = alive_;
  car->link->connect([this, alive, car](std::optional<std::string> error) {
    if (!alive.expired()) connected(*car, std::move(error));
  });
}

void Central::connected(Car& car, std::optional<std::string> error) {
  auto& q = queues_[car.adapter];
  if (q.busy == &car) q.busy = nullptr;
  if (error) {
    retryLater(car, *error);
  } else {
    car.failures = 0;
  }
  if (!car.firstAttemptDone) {
    car.firstAttemptDone = true;
    maybeFinishFirstRound();
  }
  pump(q);
}

void Central::retryLater(Car& car, const std::string& why) {
  if (shuttingDown_ || car.vanished) return;
  auto delay = options_.backoffMin;
  for (int i = 0; i < car.failures && delay < options_.backoffMax; ++i) delay *= 2;
  delay = std::min(delay, options_.backoffMax);
  ++car.failures;
  log::warn(car.car->label(), why + "; reconnecting in " + secondsText(delay));
  loop_.cancel(car.retry);
  car.retry = loop_.after(delay, [this, &car] {
    car.retry = 0;
    enqueue(car);
  });
}

void Central::vanished(Car& car) {
  car.vanished = true;
  loop_.cancel(car.retry);
  car.retry = 0;
  auto& q = queues_[car.adapter];
  q.waiting.erase(std::remove(q.waiting.begin(), q.waiting.end(), &car), q.waiting.end());
  if (shuttingDown_) return;
  log::warn(car.car->label(), car.address + " vanished: looking for it again");
  if (q.discoverers++ == 0)
    bluez_->startDiscovery(car.adapter, [](std::optional<std::string> error) {
      if (error) log::warn("ble", *error);
    });
}

void Central::deviceSeen(const Device& d) {
  for (auto& c : cars_) {
    if (!c->vanished) {
      if (c->link->devicePath() == d.path) c->link->deviceChanged(d);
      continue;
    }
    if (upper(d.address) != c->address || d.adapter != c->adapter) continue;
    c->vanished = false;
    c->link->retarget(d.path);
    log::info(c->car->label(), c->address + " is back");
    auto& q = queues_[c->adapter];
    if (--q.discoverers == 0) bluez_->stopDiscovery(c->adapter);
    enqueue(*c);
  }
}

void Central::maybeFinishFirstRound() {
  if (!firstRoundDone_) return;
  for (auto& c : cars_)
    if (!c->firstAttemptDone) return;
  auto done = std::move(firstRoundDone_);
  firstRoundDone_ = nullptr;
  done(std::nullopt);
}

void Central::reconnect() {
  shuttingDown_ = false;
  std::vector<const Adapter*> adapters;
  try {
    adapters = bluez_->pickAdapters(options_.adapters);
  } catch (const BleError& e) {
    log::warn("ble", e.what());
    return;
  }
  for (auto& c : cars_) enqueue(*c);
  std::weak_ptr<bool> alive = alive_;
  scanForCars(*bluez_, adapters, options_.scan, options_.cars,
              [this, alive](std::optional<std::string> error, std::vector<Sighting> found) {
                if (alive.expired() || shuttingDown_) return;
                if (error) return log::warn("ble", *error);
                std::vector<Sighting> fresh;
                for (auto& s : found)
                  if (std::none_of(cars_.begin(), cars_.end(),
                                   [&](const auto& c) { return c->address == s.address; }))
                    fresh.push_back(std::move(s));
                if (!fresh.empty()) addCars(fresh);
              });
}

void Central::shutdown(std::function<void()> done) {
  shuttingDown_ = true;
  for (auto& [path, q] : queues_) {
    q.waiting.clear();
    if (q.discoverers > 0) bluez_->stopDiscovery(path);
    q.discoverers = 0;
  }
  auto remaining = std::make_shared<int>(1);
  auto finish = [remaining, done] {
    if (--*remaining == 0 && done) done();
  };
  for (auto& c : cars_) {
    loop_.cancel(c->retry);
    c->retry = 0;
    ++*remaining;
    c->link->disconnect(finish);
  }
  loop_.post(finish);
}

}  // namespace pitwall::ble
