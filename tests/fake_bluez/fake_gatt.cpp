// The fake BlueZ's GATT side and links: the Anki service and characteristics of a connected car
// (or the Alphabot service and its eight characteristics), notifications (PropertiesChanged, or
// an AcquireNotify socket), writes (WriteValue, or an AcquireWrite socket), and the link to the
// simulated car or robot behind them.

#include "tests/fake_bluez/state.hpp"

namespace pitwall::testing {

// ---- GATT ----

std::unique_ptr<Characteristic> FakeBluez::State::makeCharacteristic(
    Device& d, const std::string& path, std::string_view uuid, std::vector<std::string> flags) {
  auto ch = std::make_unique<Characteristic>();
  ch->path = path;
  ch->uuid = std::string(uuid);
  ch->flags = std::move(flags);
  auto has = [&](const char* f) {
    return std::find(ch->flags.begin(), ch->flags.end(), f) != ch->flags.end();
  };
  ch->notify = has("notify");
  ch->writeCommand = has("write-without-response");
  ch->writeRequest = has("write");

  auto o = sdbus::createObject(conn, path);
  sdbus::IObject* obj = o.get();
  Device* dp = &d;
  Characteristic* cp = ch.get();
  std::string servicePath = d.path + "/service000a";

  obj->registerMethod("ReadValue")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("value")
      .implementedAs([this, dp, cp](const Dict& options) { return readValue(*dp, *cp, options); });
  obj->registerMethod("WriteValue")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("value", "options")
      .implementedAs([this, dp, cp](const std::vector<std::uint8_t>& value, const Dict& options) {
        writeValue(*dp, *cp, value, options);
      });
  obj->registerMethod("AcquireWrite")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("fd", "mtu")
      .implementedAs([this, dp, cp](const Dict&) { return acquire(*dp, *cp, true); });
  obj->registerMethod("AcquireNotify")
      .onInterface(api::kGattCharacteristic)
      .withInputParamNames("options")
      .withOutputParamNames("fd", "mtu")
      .implementedAs([this, dp, cp](sdbus::Result<sdbus::UnixFd, std::uint16_t>&& result,
                                    const Dict&) { acquireNotify(*dp, *cp, std::move(result)); });
  obj->registerMethod("StartNotify")
      .onInterface(api::kGattCharacteristic)
      .implementedAs([this, dp, cp] { startNotify(*dp, *cp); });
  obj->registerMethod("StopNotify").onInterface(api::kGattCharacteristic).implementedAs([this, cp] {
    stopNotify(*cp);
  });

  obj->registerProperty("UUID").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->uuid;
  });
  obj->registerProperty("Service").onInterface(api::kGattCharacteristic).withGetter([servicePath] {
    return sdbus::ObjectPath(servicePath);
  });
  obj->registerProperty("Value").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->value;
  });
  obj->registerProperty("Flags").onInterface(api::kGattCharacteristic).withGetter([cp] {
    return cp->flags;
  });
  // Like gatt-client.c, the notify and acquire properties exist only where the flags allow.
  if (ch->notify) {
    obj->registerProperty("Notifying").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return !cp->notifySessions.empty();
    });
    obj->registerProperty("NotifyAcquired").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return cp->notifyIo != nullptr;
    });
  }
  if (ch->writeCommand) {
    obj->registerProperty("WriteAcquired").onInterface(api::kGattCharacteristic).withGetter([cp] {
      return cp->writeIo != nullptr;
    });
  }
  obj->registerProperty("MTU").onInterface(api::kGattCharacteristic).withGetter([] {
    return kMtu;
  });
  obj->finishRegistration();
  ch->object = std::move(o);
  return ch;
}

// The device's primary service object (its UUID from serviceUuid), at <device>/service000a.
void FakeBluez::State::exportService(Device& d) {
  std::string servicePath = d.path + "/service000a";
  auto s = sdbus::createObject(conn, servicePath);
  Device* dp = &d;
  s->registerProperty("UUID").onInterface(api::kGattService).withGetter([this, dp] {
    return serviceUuid(*dp);
  });
  s->registerProperty("Primary").onInterface(api::kGattService).withGetter([] { return true; });
  s->registerProperty("Device").onInterface(api::kGattService).withGetter([dp] {
    return sdbus::ObjectPath(dp->path);
  });
  s->registerProperty("Includes").onInterface(api::kGattService).withGetter([] {
    return std::vector<sdbus::ObjectPath>{};
  });
  s->finishRegistration();
  d.service = std::move(s);
}

void FakeBluez::State::exportGatt(Device& d) {
  if (d.robot) return exportAlphabotGatt(d);
  std::string servicePath = d.path + "/service000a";
  exportService(d);
  d.readChar =
      makeCharacteristic(d, servicePath + "/char000b", anki::kReadCharUuid, {"read", "notify"});
  d.writeChar = makeCharacteristic(d, servicePath + "/char000d", anki::kWriteCharUuid,
                                   {"read", "write-without-response", "write"});
  d.service->emitInterfacesAddedSignal();
  d.readChar->object->emitInterfacesAddedSignal();
  d.writeChar->object->emitInterfacesAddedSignal();
}

// The Alphabot's service (alphabot.md §2): each characteristic with the flags of its access
// column — "write" (with response; the reference does not allow write-without-response).
void FakeBluez::State::exportAlphabotGatt(Device& d) {
  std::string servicePath = d.path + "/service000a";
  exportService(d);
  int handle = 0x0b;
  for (const auto& info : alphabot::ble::characteristics()) {
    std::vector<std::string> flags{"read"};
    if (info.write) flags.push_back("write");
    if (info.notify) flags.push_back("notify");
    char tail[16];
    std::snprintf(tail, sizeof tail, "/char%04x", handle);
    handle += 3;
    d.robotChars[static_cast<std::size_t>(info.id)] =
        makeCharacteristic(d, servicePath + tail, info.uuid, std::move(flags));
  }
  d.service->emitInterfacesAddedSignal();
  for (auto& ch : d.robotChars) ch->object->emitInterfacesAddedSignal();
}

void FakeBluez::State::removeGatt(Device& d) {
  for (auto& ch : d.robotChars) {
    if (!ch) continue;
    closeIo(ch->notifyIo);
    ch->object->emitInterfacesRemovedSignal();
    ch.reset();
  }
  for (Characteristic* ch : {d.readChar.get(), d.writeChar.get()}) {
    if (!ch) continue;
    closeIo(ch->notifyIo);
    closeIo(ch->writeIo);
    ch->object->emitInterfacesRemovedSignal();
  }
  d.readChar.reset();
  d.writeChar.reset();
  if (d.service) d.service->emitInterfacesRemovedSignal();
  d.service.reset();
}

std::vector<std::uint8_t> FakeBluez::State::readValue(Device& d, Characteristic& ch,
                                                      const Dict& options) {
  if (!d.connected) throw failed("Not connected");
  std::uint16_t offset = 0;
  if (auto it = options.find("offset"); it != options.end()) {
    if (!it->second.containsValueOfType<std::uint16_t>()) throw invalidArgs();
    offset = it->second.get<std::uint16_t>();
  }
  if (offset > ch.value.size()) throw bluezError("InvalidOffset", "Invalid offset");
  return std::vector<std::uint8_t>(ch.value.begin() + offset, ch.value.end());
}

void FakeBluez::State::writeValue(Device& d, Characteristic& ch,
                                  const std::vector<std::uint8_t>& value, const Dict& options) {
  // gatt-client.c characteristic_write_value.
  if (!d.connected) throw failed("Not connected");
  if (ch.writeIo) throw notPermitted("Write acquired");
  std::string type;
  std::uint16_t offset = 0;
  if (auto it = options.find("type"); it != options.end()) {
    if (!it->second.containsValueOfType<std::string>()) throw invalidArgs();
    type = it->second.get<std::string>();
    std::transform(type.begin(), type.end(), type.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  }
  if (auto it = options.find("offset"); it != options.end()) {
    if (!it->second.containsValueOfType<std::uint16_t>()) throw invalidArgs();
    offset = it->second.get<std::uint16_t>();
  }
  bool request;
  if (type.empty()) {
    if (ch.writeRequest)
      request = true;
    else if (ch.writeCommand && offset == 0)
      request = false;
    else
      throw notSupported();
  } else if (type == "request") {
    request = true;
  } else if (type == "command") {
    if (!ch.writeCommand || offset) throw notSupported();
    request = false;
  } else {
    throw notSupported();  // "reliable" needs the reliable-write extended property
  }
  if (request && !ch.writeRequest)
    throw notPermitted("Write not permitted");  // the car's ATT error
  if (!request && value.size() > kMtu - 3u) throw failed("Failed to initiate write");
  if (d.writesFail) throw failed("Failed to initiate write");
  toDevice(d, ch, value);
}

std::tuple<sdbus::UnixFd, std::uint16_t> FakeBluez::State::acquire(Device& d, Characteristic& ch,
                                                                   bool write) {
  // gatt-client.c characteristic_acquire_write / _notify, create_sock.
  if (options.noAcquire) throw notSupported();
  if (!d.connected) throw failed("Not connected");
  if (write) {
    if (ch.writeIo) throw notPermitted("Write acquired");
    if (!ch.writeCommand) throw notSupported();
    if (d.writesFail) throw failed("Failed to acquire write");
  } else {
    if (ch.notifyIo || d.notifyHeld) throw notPermitted("Notify acquired");
    if (!ch.notifySessions.empty()) throw inProgress();
    if (!ch.notify) throw notSupported();
  }
  int fds[2];
  if (::socketpair(AF_LOCAL, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) < 0)
    throw failed(std::strerror(errno));
  if (write) {
    ch.writeIo = std::make_unique<Io>(loop.io(), fds[0]);
    ch.writeWatched = false;  // (a wait on a closed socket before never ran to its end)
    watchWriteIo(d, ch);
    emit(ch.object.get(), api::kGattCharacteristic, {"WriteAcquired"});
  } else {
    ch.notifyIo = std::make_unique<Io>(loop.io(), fds[0]);
    watchNotifyIo(d, ch);
    emit(ch.object.get(), api::kGattCharacteristic, {"NotifyAcquired"});
  }
  log::debug(kComponent, d.address + (write ? ": write" : ": notify") + " socket acquired");
  return {sdbus::UnixFd(fds[1], sdbus::adopt_fd), kMtu};
}

void FakeBluez::State::acquireNotify(Device& d, Characteristic& ch,
                                     sdbus::Result<sdbus::UnixFd, std::uint16_t>&& result) {
  auto answer = [this](Device& dev, Characteristic& c, const auto& pending) {
    try {
      auto [fd, mtu] = acquire(dev, c, false);
      pending.returnResults(fd, mtu);
    } catch (const sdbus::Error& e) {
      pending.returnError(e);
    }
  };
  if (d.notifySlow == Duration::zero() || !d.connected || d.pendingNotify)
    return answer(d, ch, result);  // (one slow request at a time: a second is answered at once)
  log::debug(kComponent, d.address + ": AcquireNotify waits " +
                             std::to_string(toSeconds(d.notifySlow)) + " s for the car (fault)");
  auto pending = std::make_shared<sdbus::Result<sdbus::UnixFd, std::uint16_t>>(std::move(result));
  d.pendingNotify = pending;
  Device* dp = &d;
  Characteristic* cp = &ch;
  const std::uint64_t generation = d.generation;
  d.notifyTimer = after(std::exchange(d.notifySlow, Duration::zero()),
                        [this, dp, cp, generation, pending, answer] {
                          dp->notifyTimer = 0;
                          if (dp->pendingNotify != pending) return;  // abandoned meanwhile
                          dp->pendingNotify.reset();
                          if (!dp->connected || dp->generation != generation)
                            return pending->returnError(failed("Not connected"));
                          answer(*dp, *cp, *pending);
                          pump.kick();
                        });
}

void FakeBluez::State::abandonNotify(Device& d) {
  auto pending = std::move(d.pendingNotify);
  if (!pending) return;
  cancel(d.notifyTimer);
  ++d.counters.notifiesAbandoned;
  d.notifyHeld = true;  // until RemoveDevice or a restart of bluetoothd
  log::debug(kComponent, d.address +
                             ": a Disconnect while AcquireNotify waited: its notifications stay "
                             "held (BlueZ before 5.84)");
  pending->returnError(failed("Not connected"));
}

void FakeBluez::State::watchNotifyIo(Device& d, Characteristic& ch) {
  std::weak_ptr<int> token = ch.notifyIo->token;
  Device* dp = &d;
  Characteristic* cp = &ch;
  ch.notifyIo->fd.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                             [this, dp, cp, token](const boost::system::error_code& ec) {
                               if (token.expired() || ec) return;
                               // The client has nothing to send here: readable means it closed.
                               std::uint8_t buf[64];
                               ssize_t n;
                               int fd = cp->notifyIo->fd.native_handle();
                               while ((n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT)) > 0) {
                               }
                               if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                                 closeNotifyIo(*cp);
                                 pump.kick();
                                 return;
                               }
                               watchNotifyIo(*dp, *cp);
                             });
}

void FakeBluez::State::watchWriteIo(Device& d, Characteristic& ch) {
  std::weak_ptr<int> token = ch.writeIo->token;
  Device* dp = &d;
  Characteristic* cp = &ch;
  if (ch.writeWatched) return;
  ch.writeWatched = true;
  ch.writeIo->fd.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                            [this, dp, cp, token](const boost::system::error_code& ec) {
                              if (token.expired() || ec) return;
                              cp->writeWatched = false;
                              if (dp->writesHang) return;  // read again when the hang ends
                              std::uint8_t buf[512];
                              for (;;) {
                                ssize_t n = ::recv(cp->writeIo->fd.native_handle(), buf, sizeof buf,
                                                   MSG_DONTWAIT);
                                if (n > 0) {
                                  toDevice(*dp, *cp, std::span<const std::uint8_t>(buf, n));
                                  if (token.expired()) return pump.kick();
                                  continue;
                                }
                                if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                                  closeWriteIo(*cp);  // the client closed its end
                                  return pump.kick();
                                }
                                break;
                              }
                              pump.kick();
                              watchWriteIo(*dp, *cp);
                            });
}

void FakeBluez::State::closeNotifyIo(Characteristic& ch) {
  if (!ch.notifyIo) return;
  closeIo(ch.notifyIo);
  emit(ch.object.get(), api::kGattCharacteristic, {"NotifyAcquired"});
}

void FakeBluez::State::closeWriteIo(Characteristic& ch) {
  if (!ch.writeIo) return;
  closeIo(ch.writeIo);
  emit(ch.object.get(), api::kGattCharacteristic, {"WriteAcquired"});
}

void FakeBluez::State::startNotify(Device& d, Characteristic& ch) {
  // gatt-client.c characteristic_start_notify.
  if (!d.connected) throw notConnected();
  if (ch.notifyIo || d.notifyHeld) throw notPermitted("Notify acquired");
  if (!ch.notify) throw notSupported();
  std::string sender = ch.object->getCurrentlyProcessedMessage()->getSender();
  if (!ch.notifySessions.insert(sender).second) return;  // one session per client
  if (ch.notifySessions.size() == 1) emit(ch.object.get(), api::kGattCharacteristic, {"Notifying"});
}

void FakeBluez::State::stopNotify(Characteristic& ch) {
  if (ch.notifyIo) {
    closeNotifyIo(ch);
    return;
  }
  std::string sender = ch.object->getCurrentlyProcessedMessage()->getSender();
  if (!ch.notifySessions.erase(sender)) throw failed("No notify session started");
  if (ch.notifySessions.empty()) emit(ch.object.get(), api::kGattCharacteristic, {"Notifying"});
}

// ---- links ----

void FakeBluez::State::connect(Device& d, sdbus::Result<>&& result) {
  ++d.counters.connectCalls;
  if (!d.adapter->powered) return result.returnError(notReady());
  if (d.connected) return result.returnResults();  // device.c: already connected over LE
  if (d.connecting) {
    ++d.counters.connectsInProgress;
    return result.returnError(inProgress());
  }
  d.connecting = true;
  d.pendingConnect = std::make_shared<sdbus::Result<>>(std::move(result));
  if (d.connectHangs) return;  // pends: the fault's end or a Disconnect settles it
  Device* dp = &d;
  d.connectTimer = after(kConnectDelay, [this, dp] {
    dp->connectTimer = 0;
    finishConnect(*dp);
  });
}

void FakeBluez::State::finishConnect(Device& d) {
  if (d.refused) {
    log::debug(kComponent, d.address + ": connection refused (fault)");
    return failConnect(d, kConnectionAborted);
  }
  if (d.car && !d.car->connectable()) {
    log::debug(kComponent, d.address + ": not answering (it reboots)");
    return failConnect(d, kConnectionAborted);
  }
  linkUp(d);
}

void FakeBluez::State::failConnect(Device& d, const std::string& why) {
  cancel(d.connectTimer);
  d.connecting = false;
  auto pending = std::move(d.pendingConnect);
  if (pending) pending->returnError(failed(why));
}

void FakeBluez::State::linkUp(Device& d) {
  d.connecting = false;
  d.connected = true;
  ++d.generation;
  ++d.counters.connects;
  emit(d.object.get(), api::kDevice, {"Connected"});
  exportGatt(d);  // services come with the link; ServicesResolved says when they are complete

  Device* dp = &d;
  std::uint64_t generation = d.generation;
  std::weak_ptr<bool> a = alive;
  if (d.robot) {
    d.robot->connect([this, dp, generation](alphabot::ble::Characteristic c,
                                            std::span<const std::uint8_t> bytes, bool notifies) {
      if (dp->generation != generation || !dp->connected) return;
      Characteristic* ch = dp->robotChars[static_cast<std::size_t>(c)].get();
      if (!ch) return;
      ch->value.assign(bytes.begin(), bytes.end());  // served on the next read
      if (notifies && notify(*dp, ch, bytes)) pump.kick();
    });
  } else {
    d.car->connect(
        [this, dp, generation](std::span<const std::uint8_t> frame) {
          if (dp->generation != generation || !dp->connected) return;
          if (toClient(*dp, frame)) pump.kick();
        },
        [this, a, dp, generation] {
          // The car hung up (it got a disconnect frame, or went away): the link is gone. Later,
          // not now: we may be inside a method handler of an object this tears down.
          if (a.expired()) return;
          later([this, dp, generation] {
            if (dp->generation != generation || !dp->connected) return;
            log::debug(kComponent, dp->address + ": the car dropped the connection");
            linkDown(*dp, false);
          });
        });
  }

  auto pending = std::move(d.pendingConnect);
  if (pending) pending->returnResults();
  d.resolveTimer = after(kResolveDelay, [this, dp] {
    dp->resolveTimer = 0;
    dp->resolved = true;
    emit(dp->object.get(), api::kDevice, {"ServicesResolved"});
  });
  log::debug(kComponent, d.address + ": connected");

  if (!d.firstConnect) {
    d.firstConnect = loop.now();
    for (const auto& f : d.scheduled) arm(d, f);
  }
}

void FakeBluez::State::linkDown(Device& d, bool tellCar) {
  if (!d.connected) return;
  d.connected = false;
  d.resolved = false;
  ++d.generation;
  ++d.counters.disconnects;
  cancel(d.resolveTimer);
  if (auto pending = std::move(d.pendingNotify)) {  // as bluetoothd answers it on a lost link
    cancel(d.notifyTimer);
    pending->returnError(failed("Not connected"));
  }
  removeGatt(d);
  emit(d.object.get(), api::kDevice, {"ServicesResolved", "Connected"});
  if (tellCar && d.car) d.car->disconnect();  // the car stops, as on a lost link
  if (d.robot) d.robot->disconnect();
}

void FakeBluez::State::toCar(Device& d, std::span<const std::uint8_t> frame) {
  ++d.counters.framesToCar;
  d.car->receive(frame);
}

void FakeBluez::State::toDevice(Device& d, Characteristic& ch,
                                std::span<const std::uint8_t> frame) {
  if (!d.robot) return toCar(d, frame);
  ++d.counters.framesToCar;
  for (std::size_t i = 0; i < d.robotChars.size(); ++i)
    if (d.robotChars[i].get() == &ch)
      return d.robot->receive(static_cast<alphabot::ble::Characteristic>(i), frame);
}

bool FakeBluez::State::toClient(Device& d, std::span<const std::uint8_t> frame) {
  return notify(d, d.readChar.get(), frame);
}

bool FakeBluez::State::notify(Device& d, Characteristic* ch, std::span<const std::uint8_t> frame) {
  if (!ch || d.muted) {
    ++d.counters.framesDropped;
    return false;
  }
  if (ch->notifyIo) {
    // One notification, one datagram (gatt-client.c notify_io_cb); a full socket loses it.
    ssize_t n = ::send(ch->notifyIo->fd.native_handle(), frame.data(), frame.size(),
                       MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      ++d.counters.framesDropped;
      if (errno == EPIPE || errno == ECONNRESET) closeNotifyIo(*ch);
      return false;
    }
    ++d.counters.framesToClient;
    return false;
  }
  if (!ch->notifySessions.empty()) {
    ch->value.assign(frame.begin(), frame.end());
    emit(ch->object.get(), api::kGattCharacteristic, {"Value"});
    ++d.counters.framesToClient;
    return true;
  }
  ++d.counters.framesDropped;
  return false;
}

}  // namespace pitwall::testing
