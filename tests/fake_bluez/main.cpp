// fake_bluez — a fake org.bluez with simulated Anki cars (and, with --alphabots, Alphabot robots),
// on the bus named by DBUS_SYSTEM_BUS_ADDRESS. Prints `ready` once it owns org.bluez; runs until
// SIGTERM or SIGINT, then prints one line per car: `ADDR connected=… target=… connects=… …`,
// and one per Alphabot: `ADDR connected=… speed=… writes=… connects=… disconnects=…`.
#include <CLI/CLI.hpp>
#include <boost/asio/signal_set.hpp>
#include <cmath>
#include <csignal>
#include <iostream>
#include <map>

#include <sdbus-c++/sdbus-c++.h>

#include "engine/core/log.hpp"
#include "tests/fake_bluez/fake_alphabot.hpp"
#include "tests/fake_bluez/fake_bluez.hpp"

namespace {

using pitwall::testing::FakeBluez;

struct Timed {
  std::string address;
  double seconds = 0;
};

// "E0:00:00:00:00:01@2.5" → {address, 2.5}
Timed parseTimed(const std::string& flag, const std::string& text) {
  auto at = text.rfind('@');
  Timed t;
  try {
    if (at == std::string::npos) throw std::invalid_argument("no @");
    std::size_t used = 0;
    t.address = text.substr(0, at);
    t.seconds = std::stod(text.substr(at + 1), &used);
    if (used != text.size() - at - 1 || t.seconds < 0) throw std::invalid_argument("seconds");
  } catch (const std::exception&) {
    throw std::invalid_argument(flag + " '" + text +
                                "': write ADDRESS@SECONDS, e.g. E0:00:00:00:00:01@2.5 (seconds "
                                "after that car's first connection)");
  }
  return t;
}

// --fault KIND:TARGET@SECONDS[+LASTING] (see --help)
void scheduleFault(pitwall::testing::FakeBluez& fake, const std::string& text) {
  using pitwall::fromSeconds;
  using Fault = pitwall::testing::FakeBluez::Fault;
  static const std::map<std::string, Fault> kinds{{"drop", Fault::Drop},
                                                  {"burst", Fault::Burst},
                                                  {"vanish", Fault::Vanish},
                                                  {"garbage", Fault::Garbage},
                                                  {"reboot", Fault::Reboot},
                                                  {"mute", Fault::Mute},
                                                  {"writefail", Fault::WriteFail},
                                                  {"writehang", Fault::WriteHang},
                                                  {"connecthang", Fault::ConnectHang},
                                                  {"notifyheld", Fault::NotifyHeld},
                                                  {"notifyslow", Fault::NotifySlow}};
  auto bad = [&] {
    return std::invalid_argument(
        "--fault '" + text +
        "': write KIND:ADDRESS@SECONDS[+LASTING] (e.g. reboot:E0:00:00:00:00:01@30+4), "
        "unplug:hci1@60+5 or restart@90+3");
  };
  const auto at = text.rfind('@');
  if (at == std::string::npos) throw bad();
  std::string head = text.substr(0, at), when = text.substr(at + 1);
  double seconds = 0, lasting = 0;
  try {
    std::size_t used = 0;
    seconds = std::stod(when, &used);
    if (used < when.size()) {
      if (when[used] != '+') throw bad();
      std::string rest = when.substr(used + 1);
      std::size_t more = 0;
      lasting = std::stod(rest, &more);
      if (more != rest.size()) throw bad();
    }
  } catch (const std::logic_error&) {
    throw bad();
  }
  if (seconds < 0 || lasting < 0 || !std::isfinite(seconds) || !std::isfinite(lasting)) throw bad();
  if (head == "restart") return fake.restart(fromSeconds(seconds), fromSeconds(lasting));
  const auto colon = head.find(':');
  if (colon == std::string::npos) throw bad();
  std::string kind = head.substr(0, colon), target = head.substr(colon + 1);
  if (kind == "unplug") {
    if (target.rfind("hci", 0) != 0) throw bad();
    int index = std::stoi(target.substr(3));
    return fake.unplug(index, fromSeconds(seconds), fromSeconds(lasting));
  }
  auto it = kinds.find(kind);
  if (it == kinds.end()) throw bad();
  fake.schedule(it->second, target, fromSeconds(seconds), fromSeconds(lasting));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pitwall;
  CLI::App app{"fake_bluez — a fake org.bluez (BlueZ 5.66 D-Bus API) with simulated Anki cars"};
  testing::FakeBluezOptions options;
  std::vector<std::string> refuse, drop, vanish, garbage, faults;
  std::string logLevel = "info";
  app.add_option("--adapters", options.adapters, "Number of controllers, hci0… (default 1)")
      ->check(CLI::Range(0, 16));
  app.add_option("--cars", options.cars, "Number of cars, spread over the adapters (default 1)")
      ->check(CLI::Range(0, 64));
  app.add_option("--track", options.track, "Track layout: a name (oval, …) or a layout file");
  app.add_option("--seed", options.seed, "Seed of the simulator and the RSSI jitter (default 1)");
  app.add_option("--sensor", options.sensor,
                 "The cars' sensor model: real (the default) or ideal (every code)");
  app.add_option("--address", options.addresses,
                 "Address of car 1, 2, … in order (repeatable; default E0:00:00:00:00:01, …)");
  app.add_option("--name", options.names, "User name of car 1, 2, … in order (repeatable)");
  app.add_option("--refuse", refuse, "Connect to this car fails (repeatable)");
  app.add_option("--drop", drop, "ADDR@SECONDS: the link drops, the car stays known (repeatable)");
  app.add_option("--vanish", vanish, "ADDR@SECONDS: the car disconnects and is gone for good");
  app.add_option("--garbage", garbage, "ADDR@SECONDS: the car sends malformed frames");
  app.add_option("--fault", faults,
                 "KIND:ADDR@SECONDS[+LASTING]: KIND drop, burst, vanish, garbage, reboot, mute, "
                 "writefail, writehang, connecthang, notifyheld or notifyslow, seconds after that "
                 "car's first connection; "
                 "unplug:hciN@SECONDS+LASTING and restart@SECONDS+LASTING, seconds from now "
                 "(repeatable)");
  app.add_option("--alphabots", options.alphabots,
                 "Number of Alphabot robots (BLE GATT service of alphabot.md §2; default 0)")
      ->check(CLI::Range(0, 64));
  app.add_option("--alphabot-address", options.alphabotAddresses,
                 "Address of Alphabot 1, 2, … in order (repeatable; default AB:00:00:00:00:01, …)");
  app.add_option("--bystander", options.bystanders,
                 "NAME[@hciN]: a device that is not a car (a gamepad, a phone), connected to "
                 "hci0 (or hciN) from the start (repeatable)");
  app.add_flag("--no-acquire", options.noAcquire,
               "AcquireNotify/AcquireWrite answer org.bluez.Error.NotSupported");
  app.add_option("--log-level", logLevel, "debug, info, warn, error or off (default info)");
  CLI11_PARSE(app, argc, argv);

  if (auto level = log::parseLevel(logLevel)) {
    log::setLevel(*level);
  } else {
    std::cerr << "fake_bluez: --log-level '" << logLevel
              << "' is not one of debug, info, warn, error, off\n";
    return 2;
  }

  try {
    Loop loop(ClockKind::Real);
    auto connection = sdbus::createSystemBusConnection();
    FakeBluez fake(loop, *connection, options);
    for (const auto& a : refuse) fake.refuse(a);
    auto schedule = [&](const std::vector<std::string>& list, const std::string& flag,
                        FakeBluez::Fault fault) {
      for (const auto& text : list) {
        Timed t = parseTimed(flag, text);
        fake.schedule(fault, t.address, fromSeconds(t.seconds));
      }
    };
    schedule(drop, "--drop", FakeBluez::Fault::Drop);
    schedule(vanish, "--vanish", FakeBluez::Fault::Vanish);
    schedule(garbage, "--garbage", FakeBluez::Fault::Garbage);
    for (const auto& text : faults) scheduleFault(fake, text);

    boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code& ec, int) {
      if (!ec) loop.stop();
    });
    std::string list;
    for (const auto& a : fake.addresses()) list += " " + a;
    std::string robots;
    for (const auto& a : fake.alphabotAddresses()) robots += " " + a;
    log::info("fake-bluez", std::to_string(options.adapters) + " adapter(s), cars:" +
                                (list.empty() ? std::string(" none") : list) +
                                (robots.empty() ? std::string() : ", alphabots:" + robots));
    std::cout << "ready" << std::endl;
    loop.run();
    // What each car went through, for the tests to check: one line per car.
    for (const auto& a : fake.addresses()) {
      const auto& c = fake.counters(a);
      auto truth = fake.car(a).truth();
      std::cout << a << " connected=" << (fake.connected(a) ? "true" : "false")
                << " target=" << truth.target_speed_mm_s << " connects=" << c.connects
                << " disconnects=" << c.disconnects << " framesToCar=" << c.framesToCar
                << " framesToClient=" << c.framesToClient << " laps=" << truth.laps << "\n";
    }
    for (const auto& a : fake.alphabotAddresses()) {
      const auto& c = fake.counters(a);
      auto& robot = fake.alphabot(a);
      std::cout << a << " connected=" << (fake.connected(a) ? "true" : "false")
                << " speed=" << int(robot.speed()) << " writes=" << robot.writes().size()
                << " malformed=" << robot.malformedWrites() << " connects=" << c.connects
                << " disconnects=" << c.disconnects << "\n";
    }
    std::cout.flush();
    return 0;
  } catch (const sdbus::Error& e) {
    std::cerr << "fake_bluez: D-Bus: " << e.getName() << ": " << e.getMessage()
              << " (is DBUS_SYSTEM_BUS_ADDRESS set to a running bus?)\n";
  } catch (const std::exception& e) {
    std::cerr << "fake_bluez: " << e.what() << "\n";
  }
  return 1;
}
