// Bluetooth LE notification → Lua onPosition latency through a private D-Bus and the fake BlueZ,
// beside the bare path measured in the same run, on the same loop, bus and connections.
// Target: the engine adds no more than 20 % to the bare path (docs/performance.md).
//
// Everything runs in one process on one real-clock Loop: FakeBluez on one bus connection, the
// client (ble::Central + Fleet + ScriptHost) on another. One sample: t0, send a position update
// whose location id differs from the previous one, and the receiver takes t1; the next sample is
// posted only then (one at a time, no pipelining). The paths take turns sample by sample, so they
// all see the same machine; the first kWarmup samples of each are dropped.
//
// BM_BleNotifyToLuaSignal (FakeBluez with noAcquire: StartNotify, PropertiesChanged on Value):
//   bus: the fake's connection emits PropertiesChanged(org.bluez.GattCharacteristic1, Value) of
//        an object of its own under /bench (the same sdbus call the fake makes, then the fake's
//        pump kicked as inject() does); a match on the client's connection reads (s, a{sv}, as)
//        and the bytes of Value: the bare sdbus-c++ signal round trip.
//   eng: fake.inject() → PropertiesChanged → Bluez → BleLink → AnkiCar → Lua onPosition → mark().
// BM_BleNotifyToLuaAcquired (AcquireNotify: one SOCK_SEQPACKET datagram per notification):
//   sock: a socketpair of our own: send → asio async_wait on the loop → recv until EAGAIN, as
//         BleLink reads its notification socket: the bare fd path.
//   fake: the same socket sent to as inject() sends: the fake's address lookup, then the send.
//         The fake's own cost, which the engine path pays but which is not the engine (real
//         BlueZ is another process): eng − fake is the engine's receive side.
//   eng:  fake.inject() → datagram → BleLink → AnkiCar → Lua onPosition → mark().
// Counters in µs: <path>50, <path>99 (median, 99th percentile), <path>Avg, <path>Min, <path>Max;
// add50/add99 = (eng − bare)/bare in %, for the bare path (bus; sock) and, on the socket path,
// addF50/addF99 = (eng − fake)/fake. The Time column is the engine path's median.
#include <benchmark/benchmark.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/defer.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <sdbus-c++/sdbus-c++.h>

#include "bindings/script_host.hpp"
#include "engine/fleet/ble_central.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/transport/ble_link.hpp"
#include "tests/bench/frames.hpp"
#include "tests/bench/latency.hpp"
#include "tests/fake_bluez/fake_bluez.hpp"
#include "tests/support/private_bus.hpp"
#include "tests/support/run_until.hpp"

namespace {

using namespace pitwall;
using bench::positionFrame;
using namespace std::chrono_literals;

constexpr const char* kAddress = "E0:00:00:00:00:01";
constexpr std::size_t kLocationByte = 2;  // [size][id][location][piece]…
constexpr int kWarmup = 300;              // samples per path, not recorded

using Sampler = bench::Sampler;
using Stats = bench::LatencyStats;

// One car behind the fake BlueZ, connected by the Central, its onPosition handler calling mark().
struct Rig {
  testing::PrivateBus bus;
  Loop loop{ClockKind::Real};
  std::unique_ptr<sdbus::IConnection> fakeConnection = sdbus::createSystemBusConnection();
  testing::FakeBluez fake;
  Fleet fleet{loop};
  std::unique_ptr<ble::Central> central;
  std::unique_ptr<ScriptHost> host;
  AnkiCar* car = nullptr;
  Sampler sampler{loop, kWarmup, {60s}};  // no answer within 60 s: a sample got lost
  anki::Frame frame = positionFrame();
  std::string error;

  explicit Rig(bool acquire) : fake(loop, *fakeConnection, fakeOptions(acquire)) {
    ble::CentralOptions c;
    c.cars = {kAddress};
    c.scan = 2s;
    c.backoffMin = 20ms;
    c.backoffMax = 80ms;
    central = std::make_unique<ble::Central>(loop, fleet, c);
    std::optional<std::string> result = "the Central never finished its first round";
    bool finished = false;
    central->start([&](std::optional<std::string> e) {
      result = e;
      finished = true;
    });
    waitFor([&] { return finished; }, 10s);
    if (result) {
      error = *result;
      return;
    }
    if (fleet.cars().size() != 1 || !waitFor([&] { return fleet.cars()[0]->state().connected; })) {
      error = "the car did not connect";
      return;
    }
    car = fleet.cars()[0];
    if (static_cast<ble::BleLink&>(car->link()).notifyAcquired() != acquire) {
      error = acquire ? "AcquireNotify was not used" : "AcquireNotify was used";
      return;
    }
    testing::runFor(loop, 200ms);  // SDK mode and the car's answers

    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, HostOptions{});
    error = bench::startMarking(*host, sampler, "ble_bench");
    testing::runFor(loop, 10ms);  // the main chunk runs as a task
  }

  static testing::FakeBluez::Options fakeOptions(bool acquire) {
    testing::FakeBluez::Options o;
    o.noAcquire = !acquire;
    return o;
  }

  bool waitFor(const std::function<bool()>& cond, Duration deadline = 5s) {
    return testing::runUntil(loop, cond, deadline);
  }

  void inject(std::uint8_t location) {
    frame.bytes[kLocationByte] = location;
    fake.inject(kAddress, frame.span());
  }

  bool healthy() {
    if (error.empty() && host && host->errorCount() > 0) error = "the Lua handler raised an error";
    if (error.empty() && sampler.timedOut) error = "a sample got lost (no answer in 60 s)";
    return error.empty();
  }
};

// The rig, or nullptr with the benchmark skipped (no dbus-daemon, the car did not connect, …).
std::unique_ptr<Rig> makeRig(benchmark::State& state, bool acquire) {
  std::unique_ptr<Rig> rig;
  try {
    rig = std::make_unique<Rig>(acquire);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return nullptr;
  }
  if (!rig->healthy()) {
    state.SkipWithError(rig->error.c_str());
    return nullptr;
  }
  return rig;
}

void report(benchmark::State& state, const Sampler& s, const std::vector<std::string>& bare) {
  std::vector<Stats> all = s.report(state);
  std::map<std::string, Stats> st;
  for (std::size_t i = 0; i < all.size(); ++i) st[s.paths[i].name] = all[i];
  const Stats& eng = st["eng"];
  const char* names[][2] = {{"add50", "add99"}, {"addF50", "addF99"}};
  for (std::size_t i = 0; i < bare.size() && i < 2; ++i) {
    const Stats& b = st[bare[i]];
    state.counters[names[i][0]] = 100.0 * (eng.p50 - b.p50) / b.p50;
    state.counters[names[i][1]] = 100.0 * (eng.p99 - b.p99) / b.p99;
  }
  state.SetIterationTime(eng.p50 * 1e-6);
}

void BM_BleNotifyToLuaSignal(benchmark::State& state) {
  for (auto _ : state) {
    auto made = makeRig(state, false);
    if (!made) return;
    Rig& rig = *made;
    // The bare path: an object on the fake's connection with a Value property, a match on the
    // client's connection (the one the engine's Bluez pumps).
    std::vector<std::uint8_t> value;
    auto object = sdbus::createObject(*rig.fakeConnection, "/bench/char0");
    object->registerProperty("Value").onInterface(ble::kCharIface).withGetter([&] {
      return value;
    });
    object->finishRegistration();
    auto& client = rig.central->bluez().pump().connection();
    auto match = client.addMatch(
        "type='signal',interface='org.freedesktop.DBus.Properties',member='PropertiesChanged',"
        "path_namespace='/bench'",
        [&](sdbus::Message& msg) {
          std::string iface;
          std::map<std::string, sdbus::Variant> changed;
          std::vector<std::string> invalidated;
          msg >> iface >> changed >> invalidated;
          auto it = changed.find("Value");
          if (it == changed.end()) return;
          auto bytes = it->second.get<std::vector<std::uint8_t>>();
          if (bytes.size() > kLocationByte) rig.sampler.arrived(bytes[kLocationByte]);
        });
    rig.central->bluez().pump().kick();
    rig.sampler.add("bus", [&](std::uint8_t location) {
      anki::Frame f = rig.frame;
      f.bytes[kLocationByte] = location;
      value.assign(f.span().begin(), f.span().end());
      object->emitPropertiesChangedSignal(ble::kCharIface, {"Value"});
      rig.fake.pump().kick();
    });
    rig.sampler.add("eng", [&](std::uint8_t location) { rig.inject(location); });
    rig.sampler.run(static_cast<int>(state.range(0)));
    if (!rig.healthy()) {
      state.SkipWithError(rig.error.c_str());
      return;
    }
    report(state, rig.sampler, {"bus"});
  }
}
BENCHMARK(BM_BleNotifyToLuaSignal)
    ->Arg(4000)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The bare fd path: a SOCK_SEQPACKET pair like the fake's, read as BleLink reads its socket.
struct BareSocket {
  int fds[2] = {-1, -1};
  boost::asio::posix::stream_descriptor rx;
  std::function<void(long)> onDatagram;

  explicit BareSocket(Loop& loop) : rx(loop.io()) {
    if (::socketpair(AF_LOCAL, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) < 0) return;
    rx.assign(fds[0]);
  }
  ~BareSocket() {
    boost::system::error_code ec;
    rx.close(ec);
    if (fds[1] >= 0) ::close(fds[1]);
  }
  bool ok() const { return fds[1] >= 0; }
  void send(std::span<const std::uint8_t> bytes) {
    ::send(fds[1], bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  }
  void wait() {
    rx.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                  [this](const boost::system::error_code& ec) {
                    if (ec) return;
                    std::uint8_t buf[512];
                    for (;;) {
                      ssize_t n = ::recv(rx.native_handle(), buf, sizeof buf, MSG_DONTWAIT);
                      if (n > 0) {
                        if (n > static_cast<ssize_t>(kLocationByte)) onDatagram(buf[kLocationByte]);
                        continue;
                      }
                      if (n < 0 && errno == EINTR) continue;
                      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
                      return;  // closed or failed: the sample is lost, the watchdog reports it
                    }
                    wait();
                  });
  }
};

void BM_BleNotifyToLuaAcquired(benchmark::State& state) {
  for (auto _ : state) {
    auto made = makeRig(state, true);
    if (!made) return;
    Rig& rig = *made;
    BareSocket sock(rig.loop);
    if (!sock.ok()) {
      state.SkipWithError("socketpair failed");
      return;
    }
    sock.onDatagram = [&](long location) { rig.sampler.arrived(location); };
    sock.wait();
    rig.sampler.add("sock", [&](std::uint8_t location) {
      anki::Frame f = rig.frame;
      f.bytes[kLocationByte] = location;
      sock.send(f.span());
    });
    rig.sampler.add("fake", [&](std::uint8_t location) {
      if (!rig.fake.connected(kAddress)) return;  // the lookup inject() makes
      anki::Frame f = rig.frame;
      f.bytes[kLocationByte] = location;
      sock.send(f.span());  // inject() kicks the fake's pump only for a D-Bus signal
    });
    rig.sampler.add("eng", [&](std::uint8_t location) { rig.inject(location); });
    rig.sampler.run(static_cast<int>(state.range(0)));
    if (!rig.healthy()) {
      state.SkipWithError(rig.error.c_str());
      return;
    }
    report(state, rig.sampler, {"sock", "fake"});
  }
}
BENCHMARK(BM_BleNotifyToLuaAcquired)
    ->Arg(4000)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
