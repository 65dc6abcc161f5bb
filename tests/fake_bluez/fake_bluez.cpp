#include "tests/fake_bluez/fake_bluez.hpp"

// How the fake follows BlueZ 5.66 (src/adapter.c, src/device.c, src/gatt-client.c, src/eir.c,
// src/error.c), and where it does not:
// - Error names and texts are BlueZ's (error.c): StartDiscovery twice → InProgress "Operation
//   already in progress"; StopDiscovery without a start → Failed "No discovery started"; a
//   failed LE connection → Failed "le-connection-abort-by-local"; Connect on a connected device
//   succeeds at once (device.c dev_connect); Disconnect when not connected → NotConnected.
// - Name follows eir.c name2utf8 (see bluezName); no Name property when that gives "", and Alias
//   is then the address with dashes (device.c dev_property_get_alias).
// - Differences: GATT objects are removed on every disconnect (BlueZ does so only when its GATT
//   cache is off, Cache=no / Cache=yes for unpaired devices; the stock Cache=always keeps them,
//   and method calls on them then fail with Failed "Not connected"); there is no CCCD descriptor
//   object under the notify characteristic; Value exists before the first notification (empty);
//   RSSI and TxPower keep their last values after discovery stops (BlueZ invalidates them; the
//   fake then reports RSSI at the next discovery's first sighting, as BlueZ does);
//   devices stay known after discovery stops (BlueZ drops temporary ones after 30 s);
//   AdvertisingData carries the local name (0x09), which stock BlueZ does not export; method
//   replies come before the PropertiesChanged they cause in BlueZ (gdbus defers signals), here
//   the signals come first; Pair, ConnectProfile and DisconnectProfile answer NotSupported.

#include "tests/fake_bluez/state.hpp"

namespace pitwall::testing {

FakeBluez::State::State(Loop& loop_, sdbus::IConnection& connection, Options options_)
    : loop(loop_),
      conn(connection),
      options(std::move(options_)),
      pump(loop_, connection),
      rng(options.seed * 0x9e3779b97f4a7c15ull + 1) {
  // No adapter is a machine without Bluetooth hardware, where bluetoothd still runs.
  if (options.adapters < 0 || (options.adapters == 0 && options.cars > 0))
    throw std::invalid_argument("cars need an adapter: " + std::to_string(options.adapters) +
                                " adapters for " + std::to_string(options.cars) + " cars");
  if (options.cars < 0)
    throw std::invalid_argument("the number of cars cannot be negative (" +
                                std::to_string(options.cars) + ")");
  if (options.addresses.size() > static_cast<std::size_t>(options.cars))
    throw std::invalid_argument(std::to_string(options.addresses.size()) + " addresses for " +
                                std::to_string(options.cars) +
                                " cars: give at most one address per car");
  if (options.names.size() > static_cast<std::size_t>(options.cars))
    throw std::invalid_argument(std::to_string(options.names.size()) + " names for " +
                                std::to_string(options.cars) +
                                " cars: give at most one name per car");
  auto track = sim::loadLayout(options.track);
  if (!track) throw std::invalid_argument(track.error());
  world = std::make_unique<sim::World>(loop, std::move(track.value()), options.seed);
  auto sensor = sim::sensorModelNamed(options.sensor);
  if (!sensor)
    throw std::invalid_argument("sensor model '" + options.sensor +
                                "': use real, ideal or transitions");
  world->setSensor(*sensor);

  for (int i = 0; i < options.adapters; ++i) {
    auto a = std::make_unique<Adapter>();
    a->index = i;
    a->path = "/org/bluez/hci" + std::to_string(i);
    char buf[18];
    std::snprintf(buf, sizeof buf, "00:1A:7D:DA:71:%02X", i & 0xff);
    a->address = buf;
    a->name = "pitwall-fake-hci" + std::to_string(i);
    adapters.push_back(std::move(a));
  }

  std::vector<std::string> taken;
  for (int i = 0; i < options.cars; ++i) {
    sim::CarSpec spec = sim::gridSpec(world->track(), i);
    spec.name = static_cast<std::size_t>(i) < options.names.size()
                    ? options.names[i]
                    : anki::uniqueCarName(spec.model_id, taken);
    taken.push_back(spec.name);
    auto d = std::make_unique<Device>();
    d->index = i;
    d->address = static_cast<std::size_t>(i) < options.addresses.size()
                     ? normalizeAddress(options.addresses[i])
                     : defaultAddress(i);
    for (const auto& other : devices)
      if (other->address == d->address)
        throw std::invalid_argument("two cars have the address " + d->address +
                                    ": give each car its own");
    d->adapter = adapters[i % adapters.size()].get();
    std::string tail = d->address;
    std::replace(tail.begin(), tail.end(), ':', '_');
    d->path = d->adapter->path + "/dev_" + tail;
    d->car = &world->addCar(spec);
    d->baseRssi = static_cast<std::int16_t>(-50 - 6 * (i % 6));
    devices.push_back(std::move(d));
  }
  // Alphabots after the cars (fake_alphabot.hpp).
  if (options.alphabots < 0 || (options.alphabots > 0 && adapters.empty()))
    throw std::invalid_argument("alphabots need an adapter, and cannot be negative (" +
                                std::to_string(options.alphabots) + ")");
  if (options.alphabotAddresses.size() > static_cast<std::size_t>(options.alphabots))
    throw std::invalid_argument(std::to_string(options.alphabotAddresses.size()) +
                                " addresses for " + std::to_string(options.alphabots) +
                                " alphabots: give at most one address per robot");
  for (int i = 0; i < options.alphabots; ++i) {
    auto d = std::make_unique<Device>();
    d->index = i;
    if (static_cast<std::size_t>(i) < options.alphabotAddresses.size()) {
      d->address = normalizeAddress(options.alphabotAddresses[i]);
    } else {
      char buf[18];
      std::snprintf(buf, sizeof buf, "AB:00:00:00:%02X:%02X", ((i + 1) >> 8) & 0xff,
                    (i + 1) & 0xff);
      d->address = buf;
    }
    for (const auto& other : devices)
      if (other->address == d->address)
        throw std::invalid_argument("two devices have the address " + d->address +
                                    ": give each its own");
    d->adapter = adapters[(options.cars + i) % adapters.size()].get();
    std::string tail = d->address;
    std::replace(tail.begin(), tail.end(), ':', '_');
    d->path = d->adapter->path + "/dev_" + tail;
    d->robot = std::make_unique<FakeAlphabot>(loop, i);
    d->baseRssi = static_cast<std::int16_t>(-55 - 5 * (i % 6));
    devices.push_back(std::move(d));
  }

  // Bystanders last: connected to their adapter by someone else before the fake starts.
  for (std::size_t i = 0; i < options.bystanders.size(); ++i) {
    std::string spec = options.bystanders[i];
    auto d = std::make_unique<Device>();
    d->index = static_cast<int>(i);
    d->bystander = true;
    std::size_t at = spec.rfind("@hci");
    std::size_t adapter = 0;
    if (at != std::string::npos) {
      std::string index = spec.substr(at + 4);
      if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos ||
          std::stoul(index) >= adapters.size())
        throw std::invalid_argument("bystander '" + spec + "': the adapter is hci0…hci" +
                                    std::to_string(adapters.size() - 1));
      adapter = std::stoul(index);
      spec.resize(at);
    }
    if (adapters.empty()) throw std::invalid_argument("a bystander needs an adapter");
    char buf[18];
    std::snprintf(buf, sizeof buf, "BB:00:00:00:00:%02X", static_cast<unsigned>(i + 1) & 0xff);
    d->address = buf;
    d->adapter = adapters[adapter].get();
    std::string tail = d->address;
    std::replace(tail.begin(), tail.end(), ':', '_');
    d->path = d->adapter->path + "/dev_" + tail;
    d->name = spec;
    d->connected = d->resolved = true;
    devices.push_back(std::move(d));
  }

  root = sdbus::createObject(conn, "/");
  root->addObjectManager();
  for (auto& a : adapters) exportAdapter(*a);
  for (auto& d : devices)
    if (d->bystander) exportDevice(*d);

  // Discovery and notify sessions belong to the bus connection that started them.
  nameWatch = conn.addMatch(
      "type='signal',sender='org.freedesktop.DBus',path='/org/freedesktop/DBus',"
      "interface='org.freedesktop.DBus',member='NameOwnerChanged'",
      [this](sdbus::Message& m) {
        std::string name, oldOwner, newOwner;
        m >> name >> oldOwner >> newOwner;
        if (newOwner.empty() && !name.empty() && name[0] == ':') clientGone(name);
      });

  // Last: a client that sees org.bluez appear finds every object in place.
  try {
    conn.requestName("org.bluez");
  } catch (const sdbus::Error& e) {
    if (e.getName().find("EALREADY") == std::string::npos) {
      throw sdbus::Error(e.getName(), "cannot own org.bluez on this bus (" + e.getMessage() +
                                          "): is another BlueZ (or fake) running there?");
    }
  }
  pump.kick();
}

FakeBluez::State::~State() {
  alive.reset();
  for (auto id : timers) loop.cancel(id);
  timers.clear();
  nameWatch.reset();
  for (auto& d : devices) {
    if (d->connected && d->car) d->car->disconnect();  // without telling us: we are going away
    if (d->robot) d->robot->disconnect();
    for (auto& ch : d->robotChars)
      if (ch) closeIo(ch->notifyIo);
    for (auto& ch : d->robotChars) ch.reset();
    if (d->readChar) closeIo(d->readChar->notifyIo);
    if (d->writeChar) closeIo(d->writeChar->writeIo);
    d->readChar.reset();
    d->writeChar.reset();
    d->service.reset();
    d->object.reset();
  }
  for (auto& a : adapters) a->object.reset();
  root.reset();
  world.reset();
}

Loop::TimerId FakeBluez::State::after(Duration delay, std::function<void()> fn) {
  auto self = std::make_shared<Loop::TimerId>(0);
  *self = loop.after(delay, [this, self, fn = std::move(fn)] {
    timers.erase(*self);
    fn();
    pump.kick();
  });
  timers.insert(*self);
  return *self;
}

void FakeBluez::State::cancel(Loop::TimerId& id) {
  if (!id) return;
  loop.cancel(id);
  timers.erase(id);
  id = 0;
}

void FakeBluez::State::later(std::function<void()> fn) {
  std::weak_ptr<bool> a = alive;
  loop.post([this, a, fn = std::move(fn)] {
    if (a.expired()) return;
    fn();
    pump.kick();
  });
}

Device& FakeBluez::State::device(std::string_view address) {
  return const_cast<Device&>(std::as_const(*this).device(address));
}

const Device& FakeBluez::State::device(std::string_view address) const {
  // Any case, compared in place: inject() is on the benchmarks' measured path.
  auto same = [](char a, char b) {
    return std::toupper(static_cast<unsigned char>(a)) == static_cast<unsigned char>(b);
  };
  for (const auto& d : devices)
    if (std::equal(address.begin(), address.end(), d->address.begin(), d->address.end(), same))
      return *d;
  throw std::out_of_range("the fake has no car with the address '" + std::string(address) + "'");
}

void FakeBluez::State::emit(sdbus::IObject* object, const char* iface,
                            const std::vector<std::string>& props) {
  if (object) object->emitPropertiesChangedSignal(iface, props);
}

// ---- adapters ----

void FakeBluez::State::exportAdapter(Adapter& a) {
  auto o = sdbus::createObject(conn, a.path);
  sdbus::IObject* obj = o.get();
  Adapter* ap = &a;
  auto sender = [obj] { return obj->getCurrentlyProcessedMessage()->getSender(); };

  obj->registerMethod("StartDiscovery")
      .onInterface(api::kAdapter)
      .implementedAs([this, ap, sender] { startDiscovery(*ap, sender()); });
  obj->registerMethod("StopDiscovery").onInterface(api::kAdapter).implementedAs([this, ap, sender] {
    stopDiscovery(*ap, sender());
  });
  obj->registerMethod("SetDiscoveryFilter")
      .onInterface(api::kAdapter)
      .withInputParamNames("properties")
      .implementedAs([ap, sender](const Dict& dict) {
        if (!ap->powered) throw notReady();
        auto filter = parseFilter(dict);
        std::string who = sender();
        auto it = ap->clients.find(who);
        if (it != ap->clients.end()) {
          it->second.filter = filter;
          if (!filter && !it->second.discovering) ap->clients.erase(it);  // pre-set filter cleared
        } else if (filter) {
          ap->clients[who].filter = filter;  // pre-set for a later StartDiscovery
        }
      });
  obj->registerMethod("GetDiscoveryFilters")
      .onInterface(api::kAdapter)
      .withOutputParamNames("filters")
      .implementedAs([] {
        return std::vector<std::string>{"UUIDs",         "RSSI",         "Pathloss", "Transport",
                                        "DuplicateData", "Discoverable", "Pattern"};
      });
  obj->registerMethod("RemoveDevice")
      .onInterface(api::kAdapter)
      .withInputParamNames("device")
      .implementedAs([this, ap](const sdbus::ObjectPath& path) {
        for (auto& d : devices) {
          if (d->adapter == ap && d->object && d->path == path) {
            forget(*d);
            return;
          }
        }
        throw doesNotExist();
      });

  obj->registerProperty("Address").onInterface(api::kAdapter).withGetter([ap] {
    return ap->address;
  });
  obj->registerProperty("AddressType").onInterface(api::kAdapter).withGetter([] {
    return std::string("public");
  });
  obj->registerProperty("Name").onInterface(api::kAdapter).withGetter([ap] { return ap->name; });
  obj->registerProperty("Alias")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->alias.empty() ? ap->name : ap->alias; })
      .withSetter([this, ap](const std::string& v) {
        ap->alias = v;  // "" restores the system name
        emit(ap->object.get(), api::kAdapter, {"Alias"});
      });
  obj->registerProperty("Class").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{0};
  });
  obj->registerProperty("Powered")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->powered; })
      .withSetter([this, ap](const bool& on) {
        if (on == ap->powered) return;
        ap->powered = on;
        if (!on) {
          // Powering off ends discovery and every connection of this controller.
          ap->clients.clear();
          if (ap->discovering) stopScan(*ap);
          for (auto& d : devices) {
            if (d->adapter != ap) continue;
            if (d->connecting) failConnect(*d, "Not Powered");
            linkDown(*d, true);
          }
        }
        emit(ap->object.get(), api::kAdapter, {"Powered"});
      });
  obj->registerProperty("Discoverable")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->discoverable; })
      .withSetter([this, ap](const bool& v) {
        ap->discoverable = v;
        emit(ap->object.get(), api::kAdapter, {"Discoverable"});
      });
  obj->registerProperty("DiscoverableTimeout").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{180};
  });
  obj->registerProperty("Pairable")
      .onInterface(api::kAdapter)
      .withGetter([ap] { return ap->pairable; })
      .withSetter([this, ap](const bool& v) {
        ap->pairable = v;
        emit(ap->object.get(), api::kAdapter, {"Pairable"});
      });
  obj->registerProperty("PairableTimeout").onInterface(api::kAdapter).withGetter([] {
    return std::uint32_t{0};
  });
  obj->registerProperty("Discovering").onInterface(api::kAdapter).withGetter([ap] {
    return ap->discovering;
  });
  obj->registerProperty("UUIDs").onInterface(api::kAdapter).withGetter([] {
    return std::vector<std::string>{"00001801-0000-1000-8000-00805f9b34fb",   // GATT
                                    "00001800-0000-1000-8000-00805f9b34fb",   // GAP
                                    "0000180a-0000-1000-8000-00805f9b34fb"};  // Device Info
  });
  obj->registerProperty("Modalias").onInterface(api::kAdapter).withGetter([] {
    return std::string("usb:v1D6Bp0246d0542");  // BlueZ 5.66
  });
  obj->registerProperty("Roles").onInterface(api::kAdapter).withGetter([] {
    return std::vector<std::string>{"central", "peripheral"};
  });
  obj->finishRegistration();
  a.object = std::move(o);
}

// ---- discovery ----

void FakeBluez::State::startDiscovery(Adapter& a, const std::string& sender) {
  if (!a.powered) throw notReady();
  auto it = a.clients.find(sender);
  if (it != a.clients.end() && it->second.discovering) throw busy();  // one per client
  a.clients[sender].discovering = true;
  log::debug(kComponent, a.path + ": discovery started by " + sender);
  if (!a.discovering) startScan(a);
}

void FakeBluez::State::stopDiscovery(Adapter& a, const std::string& sender) {
  if (!a.powered) throw notReady();
  auto it = a.clients.find(sender);
  if (it == a.clients.end() || !it->second.discovering) throw failed("No discovery started");
  a.clients.erase(it);  // the client's filter goes with it (adapter.c discovery_stop)
  log::debug(kComponent, a.path + ": discovery stopped by " + sender);
  if (a.discovering && !a.anyDiscovering()) stopScan(a);
}

void FakeBluez::State::startScan(Adapter& a) {
  a.discovering = true;
  emit(a.object.get(), api::kAdapter, {"Discovering"});
  Adapter* ap = &a;
  int k = 0;
  for (auto& d : devices) {
    if (d->adapter != ap) continue;
    Device* dp = d.get();
    a.sightings.push_back(after(kFirstSeen + k * kSeenSpacing, [this, dp] { advertise(*dp); }));
    ++k;
  }
  armAdvertTick(a);
}

// One periodic timer per adapter while it discovers: each firing is an advertisement of every car.
void FakeBluez::State::armAdvertTick(Adapter& a) {
  Adapter* ap = &a;
  a.advertTimer = after(kAdvertPeriod, [this, ap] {
    ap->advertTimer = 0;
    for (auto& d : devices)
      if (d->adapter == ap) advertise(*d);
    if (ap->discovering) armAdvertTick(*ap);
  });
}

void FakeBluez::State::stopScan(Adapter& a) {
  a.discovering = false;
  for (auto& id : a.sightings) cancel(id);
  a.sightings.clear();
  cancel(a.advertTimer);
  for (auto& d : devices)
    if (d->adapter == &a) d->rssiStale = true;
  emit(a.object.get(), api::kAdapter, {"Discovering"});
}

bool FakeBluez::State::wanted(const Adapter& a, const Device& d, std::int16_t rssi,
                              const std::string& name) const {
  // A device is reported when any discovering client's filter lets it through
  // (adapter.c is_filter_match); a client without a filter takes everything.
  for (const auto& [who, c] : a.clients) {
    if (!c.discovering) continue;
    if (!c.filter) return true;
    const DiscoveryFilter& f = *c.filter;
    if (f.transport == "bredr") continue;  // the cars are LE only
    if (!f.uuids.empty() &&
        std::find(f.uuids.begin(), f.uuids.end(), serviceUuid(d)) == f.uuids.end())
      continue;
    if (f.rssi && rssi < *f.rssi) continue;
    if (f.pathloss && kTxPower - rssi > *f.pathloss) continue;
    if (!f.pattern.empty() && d.address.rfind(f.pattern, 0) != 0 && name.rfind(f.pattern, 0) != 0)
      continue;
    return true;
  }
  return false;
}

void FakeBluez::State::advertise(Device& d) {
  Adapter& a = *d.adapter;
  // A connected car does not advertise; a vanished one never again.
  if (!a.discovering || !a.powered || d.vanished || d.connected || d.bystander) return;
  if (d.car && !d.car->connectable()) return;  // rebooting
  std::uniform_int_distribution<int> jitter(-12, 12);
  auto rssi = static_cast<std::int16_t>(d.baseRssi + jitter(rng));
  auto manufacturer = d.car ? d.car->manufacturerData() : std::vector<std::uint8_t>{};
  auto localName = d.car ? d.car->localName() : d.robot->localName();
  std::string name = FakeBluez::bluezName(localName);
  if (!wanted(a, d, rssi, name)) return;

  if (!d.object) {
    d.rssi = rssi;
    d.manufacturer = std::move(manufacturer);
    d.localName = std::move(localName);
    d.name = std::move(name);
    exportDevice(d);
    return;
  }
  std::vector<std::string> changed;
  if (d.rssiStale || std::abs(rssi - d.rssi) >= kRssiThreshold) {
    d.rssiStale = false;
    d.rssi = rssi;
    changed.push_back("RSSI");
  }
  if (manufacturer != d.manufacturer) {
    d.manufacturer = std::move(manufacturer);
    changed.push_back("ManufacturerData");
  }
  if (localName != d.localName) {
    d.localName = std::move(localName);
    changed.push_back("AdvertisingData");
    // The Name property exists or not from the first sighting on (sdbus-c++ cannot add one).
    if (d.hasName && !name.empty() && name != d.name) {
      d.name = name;
      changed.push_back("Name");
      if (d.alias.empty()) changed.push_back("Alias");
    }
  }
  if (!changed.empty()) emit(d.object.get(), api::kDevice, changed);
}

void FakeBluez::State::clientGone(const std::string& uniqueName) {
  for (auto& a : adapters) {
    if (a->clients.erase(uniqueName) && a->discovering && !a->anyDiscovering()) {
      log::debug(kComponent, a->path + ": discovery ends, " + uniqueName + " left the bus");
      stopScan(*a);
    }
  }
  for (auto& d : devices) {
    std::vector<Characteristic*> chars{d->readChar.get()};
    for (auto& c : d->robotChars) chars.push_back(c.get());
    for (Characteristic* ch : chars)
      if (ch && ch->notifySessions.erase(uniqueName) && ch->notifySessions.empty())
        emit(ch->object.get(), api::kGattCharacteristic, {"Notifying"});
  }
}

// ---- devices ----

void FakeBluez::State::exportDevice(Device& d) {
  auto o = sdbus::createObject(conn, d.path);
  sdbus::IObject* obj = o.get();
  Device* dp = &d;

  obj->registerMethod("Connect")
      .onInterface(api::kDevice)
      .implementedAs([this, dp](sdbus::Result<>&& result) { connect(*dp, std::move(result)); });
  obj->registerMethod("Disconnect").onInterface(api::kDevice).implementedAs([this, dp] {
    // device.c: Disconnect also cancels a Connect still pending
    if (dp->connecting && !dp->connected) {
      log::debug(kComponent, dp->address + ": a pending connection cancelled by the client");
      ++dp->counters.connectsCancelled;
      return failConnect(*dp, "le-connection-abort-by-local");
    }
    if (!dp->connected) throw notConnected();
    abandonNotify(*dp);
    log::debug(kComponent, dp->address + ": disconnected by the client");
    linkDown(*dp, true);
  });
  for (const char* m : {"ConnectProfile", "DisconnectProfile"}) {
    obj->registerMethod(m)
        .onInterface(api::kDevice)
        .withInputParamNames("UUID")
        .implementedAs([](const std::string&) { throw notSupported(); });
  }
  obj->registerMethod("Pair").onInterface(api::kDevice).implementedAs([] { throw notSupported(); });
  obj->registerMethod("CancelPairing").onInterface(api::kDevice).implementedAs([] {
    throw doesNotExist();
  });

  obj->registerProperty("Address").onInterface(api::kDevice).withGetter([dp] {
    return dp->address;
  });
  obj->registerProperty("AddressType").onInterface(api::kDevice).withGetter([] {
    return std::string("random");
  });
  d.hasName = !d.name.empty();
  if (d.hasName)
    obj->registerProperty("Name").onInterface(api::kDevice).withGetter([dp] { return dp->name; });
  obj->registerProperty("Alias")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->currentAlias(); })
      .withSetter([this, dp](const std::string& v) {
        dp->alias = v;  // "" goes back to the name (or the address)
        emit(dp->object.get(), api::kDevice, {"Alias"});
      });
  obj->registerProperty("Adapter").onInterface(api::kDevice).withGetter([dp] {
    return sdbus::ObjectPath(dp->adapter->path);
  });
  obj->registerProperty("UUIDs").onInterface(api::kDevice).withGetter([this, dp] {
    return std::vector<std::string>{serviceUuid(*dp)};
  });
  obj->registerProperty("ManufacturerData").onInterface(api::kDevice).withGetter([dp] {
    // BlueZ splits the first two bytes off as the company id, little-endian: BE EF → 0xEFBE.
    std::map<std::uint16_t, sdbus::Variant> out;
    const auto& m = dp->manufacturer;
    if (m.size() >= 2) {
      auto key = static_cast<std::uint16_t>(m[0] | (m[1] << 8));
      out[key] = sdbus::Variant(std::vector<std::uint8_t>(m.begin() + 2, m.end()));
    }
    return out;
  });
  obj->registerProperty("AdvertisingData").onInterface(api::kDevice).withGetter([dp] {
    std::map<std::uint8_t, sdbus::Variant> out;
    out[0x09] = sdbus::Variant(dp->localName);  // Complete Local Name, raw
    return out;
  });
  obj->registerProperty("AdvertisingFlags").onInterface(api::kDevice).withGetter([] {
    return std::vector<std::uint8_t>{0x06};  // LE General Discoverable, BR/EDR not supported
  });
  obj->registerProperty("RSSI").onInterface(api::kDevice).withGetter([dp] { return dp->rssi; });
  obj->registerProperty("TxPower").onInterface(api::kDevice).withGetter([] { return kTxPower; });
  obj->registerProperty("Connected").onInterface(api::kDevice).withGetter([dp] {
    return dp->connected;
  });
  obj->registerProperty("ServicesResolved").onInterface(api::kDevice).withGetter([dp] {
    return dp->resolved;
  });
  obj->registerProperty("Paired").onInterface(api::kDevice).withGetter([] { return false; });
  obj->registerProperty("LegacyPairing").onInterface(api::kDevice).withGetter([] { return false; });
  obj->registerProperty("Trusted")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->trusted; })
      .withSetter([this, dp](const bool& v) {
        dp->trusted = v;
        emit(dp->object.get(), api::kDevice, {"Trusted"});
      });
  obj->registerProperty("Blocked")
      .onInterface(api::kDevice)
      .withGetter([dp] { return dp->blocked; })
      .withSetter([this, dp](const bool& v) {
        dp->blocked = v;
        emit(dp->object.get(), api::kDevice, {"Blocked"});
      });
  obj->finishRegistration();
  d.object = std::move(o);
  d.object->emitInterfacesAddedSignal();
  log::debug(kComponent, d.address + ": discovered on " + d.adapter->path);
}

void FakeBluez::State::unexportDevice(Device& d) {
  if (!d.object) return;
  d.object->emitInterfacesRemovedSignal();
  d.object.reset();
  d.alias.clear();  // BlueZ forgets what it stored about a removed device
  d.trusted = d.blocked = false;
}

// RemoveDevice: disconnect if needed, then the object goes; the next advertisement brings it back.
void FakeBluez::State::forget(Device& d) {
  if (d.connecting) failConnect(d, kConnectionAborted);
  linkDown(d, true);
  d.notifyHeld = false;  // bluetoothd lets go of what it held for the device
  unexportDevice(d);
  log::debug(kComponent, d.address + ": removed");
}

// ---- FakeBluez ----

FakeBluez::FakeBluez(Loop& loop, sdbus::IConnection& connection, Options options)
    : state_(std::make_unique<State>(loop, connection, std::move(options))) {}

FakeBluez::~FakeBluez() = default;

sim::World& FakeBluez::world() {
  return *state_->world;
}
sim::SimCar& FakeBluez::car(std::string_view address) {
  Device& d = state_->device(address);
  if (!d.car) throw std::out_of_range(d.address + " is an Alphabot, not a car");
  return *d.car;
}
std::vector<std::string> FakeBluez::addresses() const {
  std::vector<std::string> out;
  for (const auto& d : state_->devices)
    if (d->car) out.push_back(d->address);
  return out;
}
std::vector<std::string> FakeBluez::alphabotAddresses() const {
  std::vector<std::string> out;
  for (const auto& d : state_->devices)
    if (d->robot) out.push_back(d->address);
  return out;
}
FakeAlphabot& FakeBluez::alphabot(std::string_view address) {
  Device& d = state_->device(address);
  if (!d.robot) throw std::out_of_range(d.address + " is a car, not an Alphabot");
  return *d.robot;
}
std::string FakeBluez::adapterPath(int index) const {
  return state_->adapters.at(static_cast<std::size_t>(index))->path;
}
std::string FakeBluez::devicePath(std::string_view address) const {
  return state_->device(address).path;
}
bool FakeBluez::exported(std::string_view address) const {
  return state_->device(address).object != nullptr;
}
bool FakeBluez::connected(std::string_view address) const {
  return state_->device(address).connected;
}
const FakeBluez::Counters& FakeBluez::counters(std::string_view address) const {
  return state_->device(address).counters;
}
DbusPump& FakeBluez::pump() {
  return state_->pump;
}

void FakeBluez::refuse(std::string_view address, bool refused) {
  state_->device(address).refused = refused;
}
void FakeBluez::drop(std::string_view address) {
  state_->drop(state_->device(address));
  state_->pump.kick();
}
void FakeBluez::vanish(std::string_view address) {
  state_->vanish(state_->device(address));
  state_->pump.kick();
}
void FakeBluez::inject(std::string_view address, std::span<const std::uint8_t> bytes) {
  // Only a D-Bus signal needs the pump; a frame written to an acquired socket does not.
  if (state_->inject(state_->device(address), bytes)) state_->pump.kick();
}
void FakeBluez::inject(std::string_view address, alphabot::ble::Characteristic characteristic,
                       std::span<const std::uint8_t> bytes) {
  Device& d = state_->device(address);
  if (!d.connected || !d.robot) {
    log::warn(kComponent, d.address + ": not a connected Alphabot, injected bytes dropped");
    return;
  }
  auto& ch = d.robotChars[static_cast<std::size_t>(characteristic)];
  if (state_->notify(d, ch.get(), bytes)) state_->pump.kick();
}
void FakeBluez::schedule(Fault fault, std::string_view address, Duration after, Duration lasting) {
  Device& d = state_->device(address);
  d.scheduled.push_back({fault, after, lasting});
  if (d.firstConnect) state_->arm(d, d.scheduled.back());
}
void FakeBluez::unplug(int adapter, Duration after, Duration lasting) {
  Adapter* a = state_->adapters.at(static_cast<std::size_t>(adapter)).get();
  state_->after(after, [this, a, lasting] {
    state_->unplug(*a);
    state_->after(lasting, [this, a] { state_->plugBack(*a); });
  });
}
void FakeBluez::restart(Duration after, Duration lasting) {
  state_->after(after, [this, lasting] {
    state_->stopBluez();
    state_->after(lasting, [this] { state_->startBluez(); });
  });
}

std::vector<std::vector<std::uint8_t>> FakeBluez::garbageFrames() {
  return {
      {0x05, 0x17},              // the size byte promises 5 bytes, 1 follows
      {0x01},                    // a size byte and nothing else
      {0x03, 0x7e, 0x00, 0x00},  // a sane size, an id no firmware sends
  };
}

std::string FakeBluez::bluezName(std::span<const std::uint8_t> raw) {
  // eir.c name2utf8 (BlueZ 5.66): valid UTF-8 is taken whole; g_utf8_validate fails on any NUL,
  // so an Anki name goes the other way: strncpy (cut at the first NUL), non-ASCII bytes become
  // spaces, then g_strstrip. Control bytes below 0x80 (the Anki state bits) stay.
  std::string s(raw.begin(), raw.end());
  if (s.find('\0') == std::string::npos && validUtf8(s)) return s;
  s = s.substr(0, s.find('\0'));
  for (char& c : s)
    if (static_cast<unsigned char>(c) >= 0x80) c = ' ';
  auto space = [](char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
  };
  while (!s.empty() && space(s.back())) s.pop_back();
  std::size_t first = 0;
  while (first < s.size() && space(s[first])) ++first;
  return s.substr(first);
}

}  // namespace pitwall::testing
