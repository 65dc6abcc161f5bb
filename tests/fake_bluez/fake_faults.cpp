// The fake BlueZ's faults (fake_bluez.hpp, FakeBluez::Fault): a device's link dropping, the car
// rebooting, notifications lost, writes failing or stalled, malformed frames; a controller
// unplugged and plugged back; bluetoothd stopping and starting again.

#include "tests/fake_bluez/state.hpp"

namespace pitwall::testing {

void FakeBluez::State::drop(Device& d) {
  if (d.connecting) failConnect(d, kConnectionAborted);
  if (d.connected) log::debug(kComponent, d.address + ": link dropped (fault)");
  linkDown(d, true);
}

void FakeBluez::State::vanish(Device& d) {
  d.vanished = true;
  drop(d);
  unexportDevice(d);
  log::debug(kComponent, d.address + ": vanished (fault)");
}

std::string FakeBluez::State::serviceUuid(const Device& d) const {
  if (d.bystander) return "00001812-0000-1000-8000-00805f9b34fb";  // Human Interface Device
  return d.robot ? FakeAlphabot::kServiceUuid : std::string(anki::kServiceUuid);
}

bool FakeBluez::State::inject(Device& d, std::span<const std::uint8_t> bytes) {
  if (!d.connected) {
    log::warn(kComponent, d.address + ": not connected, injected bytes dropped");
    return false;
  }
  return toClient(d, bytes);
}

void FakeBluez::State::arm(Device& d, const Device::Scheduled& f) {
  Duration wait = std::max(Duration::zero(), *d.firstConnect + f.after - loop.now());
  Device* dp = &d;
  // A fault that lasts: its flag is set now and cleared after `lasting`.
  auto window = [this, dp, f](bool Device::*flag, const char* what) {
    dp->*flag = true;
    log::debug(kComponent, dp->address + ": " + what + " for " +
                               std::to_string(toSeconds(f.lasting)) + " s (fault)");
    after(f.lasting, [this, dp, flag] {
      dp->*flag = false;
      // the car answers again: an attempt still pending succeeds, as BlueZ's would
      if (flag == &Device::connectHangs && dp->connecting && !dp->connectTimer) finishConnect(*dp);
      // a write socket that was not read: read what waits in it now
      if (flag == &Device::writesHang && dp->writeChar && dp->writeChar->writeIo)
        watchWriteIo(*dp, *dp->writeChar);
    });
  };
  after(wait, [this, dp, f, window] {
    switch (f.fault) {
      case Fault::Drop:
        drop(*dp);
        break;
      case Fault::Burst:
        drop(*dp);
        for (int k = 1; k <= 2; ++k) after(k * 1500ms, [this, dp] { drop(*dp); });
        break;
      case Fault::Vanish:
        vanish(*dp);
        break;
      case Fault::Reboot:
        if (!dp->car) {
          drop(*dp);
          break;
        }
        log::debug(kComponent, dp->address + ": reboots (fault)");
        if (dp->connecting) failConnect(*dp, kConnectionAborted);
        dp->car->reboot(f.lasting);  // the car drops the link itself (linkUp's onDropped)
        break;
      case Fault::Mute:
        window(&Device::muted, "notifications lost");
        break;
      case Fault::WriteFail:
        window(&Device::writesFail, "writes fail");
        if (dp->writeChar) closeWriteIo(*dp->writeChar);
        break;
      case Fault::ConnectHang:
        window(&Device::connectHangs, "connection attempts pend");
        drop(*dp);
        break;
      case Fault::NotifyHeld:
        window(&Device::notifyHeld, "notifications held by an abandoned request");
        drop(*dp);
        break;
      case Fault::NotifySlow:
        dp->notifySlow = f.lasting;
        drop(*dp);
        break;
      case Fault::WriteHang:
        window(&Device::writesHang, "writes hang");
        break;
      case Fault::Garbage:
        if (dp->robot) {
          // Malformed SENSOR answers: degree 511, and 1 byte of 5.
          auto* sensor =
              dp->robotChars[static_cast<std::size_t>(alphabot::ble::Characteristic::Sensor)].get();
          for (const auto& frame :
               std::vector<std::vector<std::uint8_t>>{{0x81, 0xff, 0, 0, 0}, {0x81}})
            if (dp->connected) notify(*dp, sensor, frame);
          break;
        }
        for (const auto& frame : FakeBluez::garbageFrames()) inject(*dp, frame);
        break;
    }
  });
}

// The controller leaves: its links end (the cars stop), its devices and itself leave the bus.
void FakeBluez::State::unplug(Adapter& a) {
  if (!a.plugged) return;
  log::debug(kComponent, a.path + ": unplugged (fault)");
  for (auto& d : devices) {
    if (d->adapter != &a) continue;
    if (d->connecting) failConnect(*d, kConnectionAborted);
    linkDown(*d, true);
    unexportDevice(*d);
  }
  if (a.discovering) stopScan(a);
  a.clients.clear();
  a.plugged = false;
  if (a.object) a.object->emitInterfacesRemovedSignal();
  a.object.reset();
}

void FakeBluez::State::plugBack(Adapter& a) {
  if (a.plugged || !running) return;
  log::debug(kComponent, a.path + ": plugged back (fault)");
  a.plugged = true;
  exportAdapter(a);
  a.object->emitInterfacesAddedSignal();
}

// bluetoothd stops: its connections end with it and its objects go with its name.
void FakeBluez::State::stopBluez() {
  if (!running) return;
  log::debug(kComponent, "bluetoothd stops (fault)");
  for (auto& d : devices) {
    if (d->connecting) failConnect(*d, kConnectionAborted);
    linkDown(*d, true);
    d->notifyHeld = false;  // a new bluetoothd holds nothing
    d->object.reset();      // no signal: the process that owned it is gone
    d->alias.clear();
    d->trusted = d->blocked = false;
  }
  for (auto& a : adapters) {
    if (a->discovering) stopScan(*a);
    a->clients.clear();
    a->object.reset();
  }
  running = false;
  conn.releaseName("org.bluez");
}

void FakeBluez::State::startBluez() {
  if (running) return;
  log::debug(kComponent, "bluetoothd starts again (fault)");
  running = true;
  for (auto& a : adapters)
    if (a->plugged) exportAdapter(*a);
  conn.requestName("org.bluez");  // a client reads the tree when it sees the name come back
}

}  // namespace pitwall::testing
