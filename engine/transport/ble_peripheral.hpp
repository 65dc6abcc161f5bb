#pragma once
// A BLE peripheral through BlueZ's D-Bus API (gatt-api, advertising-api): one primary GATT
// service with a notify characteristic (peripheral → central) and a write characteristic
// (central → peripheral), and an LE advertisement that carries the service UUID, manufacturer
// data and a local name. This is what an Anki car looks like to a controller; `pitwall
// emulate-car` puts a simulated car behind it (tests/qemu: the real bluetoothd end to end).
//
// Everything runs on the engine loop through a DbusPump: calls to BlueZ are asynchronous, and
// BlueZ's calls into the application (ReadValue, WriteValue, StartNotify, …) are answered on the
// loop. One central at a time, as on a car.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/transport/dbus_pump.hpp"

namespace pitwall {

struct PeripheralSpec {
  std::string adapter = "hci0";  // BlueZ adapter name: /org/bluez/<adapter>
  std::string serviceUuid;
  std::string notifyCharUuid;                  // flags read, notify
  std::string writeCharUuid;                   // flags write, write-without-response
  std::uint16_t manufacturerKey = 0;           // company id: the first 2 bytes, little-endian
  std::vector<std::uint8_t> manufacturerData;  // the bytes after the company id
  std::vector<std::uint8_t> localName;         // raw bytes (may hold NULs), tried first
  // The LocalName string when the raw bytes are refused: UTF-8 without NUL (a D-Bus string),
  // control characters allowed (emulate-car's Anki-shaped name, anki::localNameText).
  std::string localNameText;
};

class BlePeripheral {
 public:
  // The pump's connection must be a bus connection that BlueZ can call back (the system bus).
  BlePeripheral(DbusPump& pump, PeripheralSpec spec);
  ~BlePeripheral();
  BlePeripheral(const BlePeripheral&) = delete;
  BlePeripheral& operator=(const BlePeripheral&) = delete;

  // Checks the adapter, registers the GATT application, then the advertisement. `done` gets ""
  // once BlueZ accepted both, or one sentence saying what was wrong and what to do.
  void start(std::function<void(const std::string& error)> done);
  // Unregisters both; `done` runs once BlueZ answered both calls (the caller bounds the wait).
  void stop(std::function<void()> done);

  // A notification on the notify characteristic; dropped (false) while no central subscribed.
  bool notify(std::span<const std::uint8_t> value);
  // Asks BlueZ to drop the central (as a car does when told to disconnect).
  void disconnectCentral();

  // How the local name went into the advertisement, once start() succeeded: e.g.
  // `Data 0x09 (20 raw bytes)` or `LocalName "\x10p+\x01\x01\x01\x01\x01pitwall" (scan
  // response)`, control characters written as \xNN.
  const std::string& advertisedName() const;
  bool connected() const;

  // A central subscribed to notifications (or wrote before subscribing): the link is up.
  std::function<void(const std::string& device)> onConnected;
  // The central wrote to the write characteristic (one write is one frame).
  std::function<void(std::span<const std::uint8_t>)> onWrite;
  // The central unsubscribed or disconnected; the peripheral advertises again.
  std::function<void()> onDisconnected;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace pitwall
