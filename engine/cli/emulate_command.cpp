// pitwall emulate-car: one simulated car behind a BLE peripheral, so that a central (pitwall run
// --ble, or any Anki app) can find it, connect and drive it through the real BlueZ stack.
#include <boost/asio/signal_set.hpp>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>

#include <sdbus-c++/sdbus-c++.h>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/ble_peripheral.hpp"
#include "engine/transport/dbus_pump.hpp"

namespace pitwall::cli {
namespace {

constexpr const char* kComponent = "emulate-car";
// How long a stop waits for BlueZ to confirm the unregistrations before leaving anyway (the
// registrations also die with our bus connection).
constexpr Duration kStopGrace = std::chrono::seconds(1);
// The simulator's "fully charged" (engine/sim: at or above it, the state byte's 0x10 bit).
constexpr std::uint16_t kFullBatteryMv = 4200;

std::string hex32(std::uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

}  // namespace

int emulateCar(const EmulateOptions& options) {
  if (auto problem = anki::userNameProblem(options.name); !problem.empty()) {
    return fail("emulate-car", "--name: " + problem);
  }
  auto track = sim::loadLayout(options.track);
  if (!track) {
    return fail("emulate-car", track.error());
  }

  std::unique_ptr<sdbus::IConnection> bus;
  try {
    bus = sdbus::createSystemBusConnection();
  } catch (const sdbus::Error& e) {
    return fail("emulate-car", "cannot connect to the system bus (" + e.getMessage() +
                                   "): is D-Bus running? (DBUS_SYSTEM_BUS_ADDRESS chooses another "
                                   "bus)");
  }

  Loop loop(ClockKind::Real);
  log::setTimeSource([&loop] { return loop.seconds(); });
  sim::World world(loop, std::move(*track), options.seed);
  world.setSensor(sim::sensorModelNamed(options.sensor).value_or(sim::SensorModel::Real));
  sim::CarSpec spec = sim::gridSpec(world.track(), 0);
  spec.name = options.name;
  spec.model_id = options.model;
  // Fully charged, as a car just taken off its charger: its name's state byte is 0x10 "full
  // battery". A battery neither full nor low is state 0, a NUL the text name cannot hold.
  spec.battery_mv = kFullBatteryMv;
  spec.version = options.firmware;
  sim::SimCar& car = world.addCar(spec);

  PeripheralSpec peripheralSpec;
  peripheralSpec.adapter = options.adapter;
  peripheralSpec.serviceUuid = anki::kServiceUuid;
  peripheralSpec.notifyCharUuid = anki::kReadCharUuid;
  peripheralSpec.writeCharUuid = anki::kWriteCharUuid;
  // 8 bytes [BE EF][reserved][model][id]: BlueZ takes the first two as the company id.
  auto manufacturer = car.manufacturerData();
  peripheralSpec.manufacturerKey = anki::kManufacturerKey;
  peripheralSpec.manufacturerData.assign(manufacturer.begin() + 2, manufacturer.end());
  peripheralSpec.localName = car.localName();
  if (options.plainName) {
    peripheralSpec.localNameText = options.name;
  } else {
    // The car's own local name (state, version, user name) with filler for its zeros: clients
    // such as py-drivesdk read byte 0 as the state and skip a car "on the charger" — which the
    // plain name's first letter often is ('p' is 0x70).
    anki::LocalName local = anki::parseLocalName(car.localName());
    local.user_name = options.name;  // whole: the simulator's bytes keep 11 of its 12
    auto text = anki::localNameText(local);
    if (!text) {
      return fail("emulate-car", "cannot advertise the car's local name: " + text.error() +
                                     " (--plain-name advertises the name alone)");
    }
    peripheralSpec.localNameText = *text;
  }

  DbusPump pump(loop, *bus);
  BlePeripheral peripheral(pump, peripheralSpec);
  const std::string who = "'" + options.name + "' (" + anki::modelName(options.model) + ", id " +
                          hex32(car.identifier()) + ")";

  int status = 0;
  bool stopping = false;
  auto finish = [&](int code) {
    if (stopping) return;
    stopping = true;
    status = code;
    car.disconnect();
    peripheral.stop([&] { loop.stop(); });
    loop.after(kStopGrace, [&] { loop.stop(); });
  };

  int lapsAtConnect = 0;
  peripheral.onConnected = [&](const std::string& device) {
    log::info(kComponent, "a central connected (" + device + ")");
    lapsAtConnect = car.truth().laps;
    car.connect([&](std::span<const std::uint8_t> frame) { peripheral.notify(frame); },
                [&] {
                  log::info(kComponent, "the car dropped the connection");
                  peripheral.disconnectCentral();
                });
  };
  peripheral.onWrite = [&](std::span<const std::uint8_t> frame) { car.receive(frame); };
  peripheral.onDisconnected = [&] {
    log::info(kComponent, "the central went away after " +
                              std::to_string(car.truth().laps - lapsAtConnect) +
                              " lap(s); advertising again");
    car.disconnect();
  };

  peripheral.start([&](const std::string& error) {
    if (!error.empty()) {
      fail("emulate-car", error);
      status = 2;
      stopping = true;
      loop.stop();
      return;
    }
    log::info(kComponent, "advertising " + who + " on " + options.adapter +
                              "; local name: " + peripheral.advertisedName());
  });

  // Progress while a central drives: one line per lap.
  int reported = 0;
  std::function<void()> watchLaps = [&] {
    int now = car.truth().laps;
    if (now != reported) {
      reported = now;
      log::info(kComponent, "lap " + std::to_string(now));
    }
    loop.after(std::chrono::milliseconds(250), watchLaps);
  };
  watchLaps();

  boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    log::info(kComponent, std::string(sig == SIGINT ? "interrupted" : "terminated") +
                              ": unregistering from BlueZ");
    finish(0);
  });
  if (options.duration)
    loop.after(fromSeconds(*options.duration), [&] {
      log::info(kComponent, "the duration is over: unregistering from BlueZ");
      finish(0);
    });

  loop.run();
  car.disconnect();  // no callback into the peripheral from here on
  log::setTimeSource(nullptr);
  return status;
}

Command addEmulateCommand(CLI::App& app) {
  auto emulate = std::make_shared<EmulateOptions>();
  auto* cmd = app.add_subcommand(
      "emulate-car", "Be an Anki car: a BLE peripheral driven by the simulator (needs BlueZ)");
  cmd->add_option("--adapter", emulate->adapter, "The controller to advertise on (hci0)");
  cmd->add_option("--name", emulate->name, "The car's user name (pitwall, ≤ 12 bytes)");
  cmd->add_flag("--plain-name", emulate->plainName,
                "Advertise the user name alone, not laid out as a car's local name");
  cmd->add_option("--model", emulate->model, "Model id (8: Groundshock)")
      ->check(CLI::Range(1, 255));
  cmd->add_option("--track", emulate->track, "Track layout the car drives on (oval)");
  cmd->add_option("--seed", emulate->seed, "Seed of the simulator");
  cmd->add_option("--sensor", emulate->sensor,
                  "What the car's sensor reports: real (as real cars do; the default) or ideal "
                  "(every code)")
      ->check(CLI::IsMember({"real", "ideal", "transitions"}));
  addFirmware(cmd, emulate->firmware, "the car");
  cmd->add_option("--duration", emulate->duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);
  return {cmd, [emulate] { return cli::emulateCar(*emulate); }};
}

}  // namespace pitwall::cli
