// The MQTT bridge through a real broker (issue 7): how many vehicle messages a bridged fleet gets
// through, and how long a car's frame takes from one host to a Lua callback on another.
//
// Everything runs in one process on one real-clock Loop, against a private mosquitto on a free
// loopback port (tests/support/mosquitto_broker.hpp); every message goes through the broker over
// loopback TCP. "Host A" is a Fleet whose cars sit on CarLinks (below) with an MqttBridge on its
// own MqttClient; "host B" is another MqttClient: a plain subscriber, or RemoteCars feeding
// AnkiCars of a second Fleet (and a Lua ScriptHost). The broker is the only other process.
//
// BM_MqttBridgeThroughput/<cars>/<window>/<broker_nodelay>: position updates injected on A round
//   robin over the cars, as fast as B takes them: at most <window> updates' worth of messages
//   (window × 10) published and not yet received on B (the broker's queue for a client holds
//   1000 messages; beyond that it drops them);
//   B is a plain client subscribed to Anki/Car/+/E/# (QoS 0) and Anki/Car/+/S/# (QoS 1), a
//   superset of what RemoteCars subscribes to. One position update = 10 publications (E/frame,
//   6 events, the controller's E/Messages/…POSITION_UPDATE, 2 retained status at QoS 1).
//   Time: first injection → last message on B. items_per_second = vehicle messages received on
//   B; counters upd_per_s (position updates/s), pub_per_s (the bridge's
//   publications/s), lost (messages expected on B and never seen; lost_frame, lost_status by
//   kind), a_us (thread CPU µs per update spent on host A's side: AnkiCar::receive → bridge →
//   publish), cpu_us (this thread's CPU µs per update, A and B), broker_us (mosquitto's CPU µs
//   per update, from /proc).
// BM_MqttRemoteThroughput/<cars>/<window>/<broker_nodelay>: the same with B = RemoteCars, which
//   takes 4 messages per update (E/frame, E/Messages and the 2 status; not the other events), so
//   the window is window × 4 messages: items are the frames that reach B's AnkiCars
//   (AnkiCar::receive), counted by B's Fleet::frames.
// BM_MqttFrameToLua/<samples>/<broker_nodelay>: one sample at a time (tests/bench/latency.hpp):
//   t0, inject a position update on A's car, t1 when B's Lua onPosition handler calls
//   mark(ev.location). Path `eng`:
//   AnkiCar::receive → MqttBridge (10 publications, E/frame first) → broker → RemoteCars →
//   AnkiCar::receive → Lua. Path `raw`, taking turns with it: a bare libmosquitto round trip
//   through the same broker, one QoS-0 message of the same size as E/frame between two other
//   MqttClients. Counters in µs: <path>50, <path>99 (nearest rank), <path>Avg, <path>Min,
//   <path>Max; the Time column is eng50.
// broker_nodelay (every benchmark): the broker's set_tcp_nodelay (BrokerOptions::tcpNoDelay),
//   1 as docs/mqtt.md recommends and the tests' brokers run, 0 mosquitto's default (Nagle's
//   algorithm on the broker's sockets). The clients are always as shipped: MqttClient sets
//   TCP_NODELAY, and MqttBridge corks one frame's publications (MqttClient::Batch).
#include <benchmark/benchmark.h>
#include <dirent.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/defer.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/mqtt/bridge.hpp"
#include "engine/mqtt/remote.hpp"
#include "engine/mqtt/topics.hpp"
#include "engine/protocol/anki/codec.hpp"
#include "engine/transport/mqtt_client.hpp"
#include "tests/bench/frames.hpp"
#include "tests/bench/latency.hpp"
#include "tests/support/mosquitto_broker.hpp"
#include "tests/support/run_until.hpp"

namespace {

using namespace pitwall;
using namespace std::chrono_literals;
using bench::kLocationByte;
using bench::positionFrame;
using Clock = std::chrono::steady_clock;

// E/frame + 6 events + E/Messages/…POSITION_UPDATE + 2 status (engine/mqtt/topics.cpp)
constexpr int kPublicationsPerUpdate = 10;

// A car of host A: connected from the start, with a BLE-like address of its own so that every
// car gets its own topic id (BenchLink's "bench" would give them all one).
class CarLink final : public Link {
 public:
  explicit CarLink(int n) {
    char a[32];
    std::snprintf(a, sizeof a, "ble:E0:00:00:00:00:%02X", n & 0xff);
    address_ = a;
  }
  bool send(std::span<const std::uint8_t>) override { return true; }
  bool connected() const override { return true; }
  void disconnect() override {}
  std::string address() const override { return address_; }

 private:
  std::string address_;
};

struct ThreadCpuClock {
  static double seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
  }
};

// CPU seconds (user + system) used so far by the mosquitto child of this process; 0 if unknown.
double brokerCpuSeconds() {
  DIR* d = ::opendir("/proc/self/task");
  if (!d) return 0;
  double secs = 0;
  while (dirent* e = ::readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream children(std::string("/proc/self/task/") + e->d_name + "/children");
    for (long pid; children >> pid;) {
      std::ifstream comm("/proc/" + std::to_string(pid) + "/comm");
      std::string name;
      if (!(comm >> name) || name != "mosquitto") continue;
      std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
      std::string line;
      std::getline(stat, line);
      auto close = line.rfind(')');
      if (close == std::string::npos) continue;
      std::istringstream rest(line.substr(close + 2));
      std::string field;
      unsigned long long utime = 0, stime = 0;
      for (int i = 3; i <= 15 && rest >> field; ++i) {  // fields 14 and 15 of stat(5)
        if (i == 14) utime = std::stoull(field);
        if (i == 15) stime = std::stoull(field);
      }
      secs += static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
    }
  }
  ::closedir(d);
  return secs;
}

MqttOptions clientOptions(const testing::MosquittoBroker& broker, const std::string& id) {
  MqttOptions o = MqttOptions::fromUrl(broker.url());
  o.clientId = id;
  return o;
}

// The broker, host A (`cars` cars on CarLinks, bridged as host "bench-a") and host B's client.
struct Rig {
  std::unique_ptr<testing::MosquittoBroker> broker;
  Loop loop{ClockKind::Real};
  Fleet fleetA{loop};
  std::vector<AnkiCar*> carsA;
  std::unique_ptr<MqttClient> clientA;
  std::unique_ptr<MqttBridge> bridge;
  std::unique_ptr<MqttClient> clientB;  // "bench-b", unconnected: each benchmark makes it B
  bool synced = false;                  // B's onMessage sets it for the topic bench/sync
  anki::Frame frame = positionFrame();
  std::string error;

  Rig(int cars, bool brokerNoDelay) {
    testing::BrokerOptions b;
    b.tcpNoDelay = brokerNoDelay;
    broker = std::make_unique<testing::MosquittoBroker>(b);
    for (int i = 0; i < cars; ++i)
      carsA.push_back(&fleetA.add(std::make_unique<CarLink>(i + 1), CarIdentity{}));
    MqttOptions o = clientOptions(*broker, "bench-a");
    o.will = MqttBridge::will("bench-a");
    clientA = std::make_unique<MqttClient>(loop, o);
    bridge = std::make_unique<MqttBridge>(loop, fleetA, *clientA, BridgeOptions{"bench-a", false},
                                          CarConnections{});
    clientB = std::make_unique<MqttClient>(loop, clientOptions(*broker, "bench-b"));
  }

  bool connect(MqttClient& c) {
    c.connect();
    if (!testing::runUntil(loop, [&] { return c.state() == MqttClient::State::Connected; }))
      error = "client " + c.options().clientId + " did not connect to the broker (state " +
              std::to_string(static_cast<int>(c.state())) + ")";
    return error.empty();
  }
  // Starts `remote` (host B's RemoteCars) and waits until `cars` cars are online there.
  bool startRemote(RemoteCars& remote, std::size_t cars) {
    bool synced = false;
    std::string failed;
    remote.start([&] { synced = true; }, [&](const std::string& why) { failed = why; });
    bool done = testing::runUntil(
        loop, [&] { return !failed.empty() || (synced && remote.onlineCount() == cars); });
    if (!failed.empty())
      error = failed;
    else if (!done)
      error = "the remote cars did not come online on host B";
    return error.empty();
  }

  // Waits until everything published so far reached B: B publishes a marker to itself (QoS 1,
  // delivered after what the broker already had for it); B must be subscribed to bench/sync.
  bool drain() {
    synced = false;
    clientB->publish("bench/sync", "{}", 1, false);
    return testing::runUntil(
        loop, [&] { return synced; }, 10s);
  }

  void inject(std::size_t car, std::uint8_t location) {
    frame.bytes[kLocationByte] = location;
    carsA[car]->receive(frame.span());
  }
};

// The rig, or nullptr with the benchmark skipped (no mosquitto, no free port, …).
std::unique_ptr<Rig> makeRig(benchmark::State& state, int cars, bool brokerNoDelay) {
  try {
    return std::make_unique<Rig>(cars, brokerNoDelay);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return nullptr;
  }
}

// ---- throughput ----

// Runs `total` updates through A with at most `window` updates' worth of messages in flight; B
// calls received() for every vehicle message (and frameReceived() for each frame). Stops when B
// has everything, or when nothing arrived for 1 s (something was lost).
struct Pump {
  Rig& rig;
  long window = 0, total = 0, sent = 0, frames = 0, messages = 0, expected = 0, status = 0;
  long delivered = 0;                       // RemoteCars: frames that reached host B's AnkiCars
  long perUpdate = kPublicationsPerUpdate;  // messages B subscribes to per position update
  long lastSeen = -1;
  Clock::time_point t0, tLast;
  double aCpu = 0;                // thread CPU spent injecting (host A's side)
  double cpu = 0, brokerCpu = 0;  // this thread's and the broker's CPU seconds in the run
  bool queued = false, stalled = false;
  bool counting = false;  // from the first run on (not the retained state at subscription)
  bool running = false;   // inside run(): timed
  Loop::TimerId watch = 0;
  int idleTicks = 0;

  Pump(Rig& r, long windowUpdates, long messagesPerUpdate)
      : rig(r), window(windowUpdates), perUpdate(messagesPerUpdate) {}

  void pump() {
    queued = false;
    double c0 = ThreadCpuClock::seconds();
    // Bounded by every message, not only by frames: status (QoS 1) can lag behind the events.
    while (sent < total && sent * perUpdate - messages < window * perUpdate) {
      rig.inject(static_cast<std::size_t>(sent) % rig.carsA.size(),
                 static_cast<std::uint8_t>(sent & 0xff));
      ++sent;
    }
    aCpu += ThreadCpuClock::seconds() - c0;
  }
  void schedule() {
    if (queued || sent >= total) return;
    queued = true;
    boost::asio::defer(rig.loop.io(), [this] { pump(); });
  }
  void received() {
    if (!counting) return;
    ++messages;  // after a stalled run, late ones still count as received, not as time
    if (!running) return;
    schedule();
    tLast = Clock::now();
    if (messages >= expected && sent >= total) rig.loop.stop();
  }
  void frameReceived() {
    if (!counting) return;
    ++frames;
  }
  // One run of `n` updates.
  void run(long n) {
    total = n;
    sent = frames = messages = status = delivered = 0;
    expected = n * perUpdate;
    aCpu = 0;
    stalled = false;
    idleTicks = 0;
    lastSeen = -1;
    std::function<void()> check = [&] {
      watch = 0;
      if (messages == lastSeen) {
        if (++idleTicks >= 20) {  // 1 s without a message
          stalled = true;
          return rig.loop.stop();
        }
      } else {
        idleTicks = 0;
        lastSeen = messages;
      }
      watch = rig.loop.after(50ms, check);
    };
    watch = rig.loop.after(50ms, check);
    t0 = tLast = Clock::now();
    counting = running = true;
    double cpu0 = ThreadCpuClock::seconds(), broker0 = brokerCpuSeconds();
    rig.loop.post([this] { pump(); });
    rig.loop.run();
    running = false;
    cpu = ThreadCpuClock::seconds() - cpu0;
    brokerCpu = brokerCpuSeconds() - broker0;
    if (watch) rig.loop.cancel(watch);
  }
};

bool isVehicleTopic(std::string_view t) {
  return t.starts_with("Anki/Car/");
}
bool isFrameTopic(std::string_view t) {
  return t.ends_with("/E/frame");
}

constexpr long kWarmupUpdates = 2000;
constexpr long kUpdates = 10000;

// After B is connected and has everything so far: kWarmupUpdates, then kUpdates timed, and the
// counters. `items`: the Pump's counter of what counts as items, read after the run (B's messages,
// or frames into B's cars).
void measure(benchmark::State& state, Rig& rig, Pump& p, const long& items) {
  p.run(kWarmupUpdates);
  rig.drain();
  auto published0 = rig.bridge->stats().published;
  auto dropped0 = rig.bridge->stats().dropped;
  p.run(kUpdates);
  if (p.stalled) rig.drain();  // the late ones count as received, and as not lost

  double secs = std::chrono::duration<double>(p.tLast - p.t0).count();
  state.SetIterationTime(secs);
  state.SetItemsProcessed(items);
  state.counters["msg_per_s"] = static_cast<double>(p.messages) / secs;
  state.counters["upd_per_s"] = static_cast<double>(p.total) / secs;
  state.counters["pub_per_s"] =
      static_cast<double>(rig.bridge->stats().published - published0) / secs;
  state.counters["lost"] = static_cast<double>(p.expected - p.messages);
  if (p.status) {  // the plain subscriber: which kind was lost
    state.counters["lost_frame"] = static_cast<double>(p.total - p.frames);
    state.counters["lost_status"] = static_cast<double>(2 * p.total - p.status);
  }
  state.counters["a_us"] = 1e6 * p.aCpu / static_cast<double>(p.total);
  state.counters["cpu_us"] = 1e6 * p.cpu / static_cast<double>(p.total);
  state.counters["broker_us"] = 1e6 * p.brokerCpu / static_cast<double>(p.total);
  state.counters["dropped"] = static_cast<double>(rig.bridge->stats().dropped - dropped0);
}

void BM_MqttBridgeThroughput(benchmark::State& state) {
  for (auto _ : state) {
    auto made = makeRig(state, static_cast<int>(state.range(0)), state.range(2) != 0);
    if (!made) return;
    Rig& rig = *made;
    MqttClient& b = *rig.clientB;
    Pump p(rig, state.range(1), kPublicationsPerUpdate);
    b.subscribe("Anki/Car/+/E/#", 0);
    b.subscribe("Anki/Car/+/S/#", 1);
    b.subscribe("bench/sync", 1);
    b.onMessage = [&](std::string_view topic, std::string_view, bool) {
      if (topic == "bench/sync") {
        rig.synced = true;
        return;
      }
      if (!isVehicleTopic(topic)) return;
      if (p.counting && topic.find("/S/") != std::string_view::npos) ++p.status;
      p.received();
      if (isFrameTopic(topic)) p.frameReceived();
    };
    if (!rig.connect(*rig.clientA) || !rig.connect(b) || !rig.drain()) {
      state.SkipWithError(rig.error.empty() ? "no sync marker" : rig.error.c_str());
      return;
    }
    measure(state, rig, p, p.messages);
  }
}
BENCHMARK(BM_MqttBridgeThroughput)
    ->ArgNames({"cars", "window", "broker_nodelay"})
    ->Args({1, 16, 1})
    ->Args({1, 64, 1})
    ->Args({4, 16, 1})
    ->Args({4, 64, 1})
    ->Args({4, 256, 1})
    ->Args({4, 64, 0})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

void BM_MqttRemoteThroughput(benchmark::State& state) {
  const int cars = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto made = makeRig(state, cars, state.range(2) != 0);
    if (!made) return;
    Rig& rig = *made;
    MqttClient& b = *rig.clientB;
    Fleet fleetB(rig.loop);
    RemoteCars remote(rig.loop, fleetB, b);
    // RemoteCars takes E/frame, E/Messages and the 2 status, not the other events
    Pump p(rig, state.range(1), 4);
    b.subscribe("bench/sync", 1);
    auto inner = b.onMessage;
    b.onMessage = [&](std::string_view topic, std::string_view payload, bool retained) {
      if (topic == "bench/sync") rig.synced = true;
      inner(topic, payload, retained);  // a frame reaches B's car (and Fleet::frames) in here
      if (isVehicleTopic(topic)) p.received();
    };
    auto counting = fleetB.frames.connect(
        [&](AnkiCar&, AnkiCar::Direction d, std::span<const std::uint8_t>, const anki::Message&) {
          if (d == AnkiCar::Direction::Rx && p.counting) ++p.delivered;
        });
    if (!rig.connect(*rig.clientA) || !rig.startRemote(remote, static_cast<std::size_t>(cars))) {
      state.SkipWithError(rig.error.c_str());
      return;
    }
    rig.drain();
    measure(state, rig, p, p.delivered);
    state.counters["lost_frame"] = static_cast<double>(p.total - p.delivered);
  }
}
BENCHMARK(BM_MqttRemoteThroughput)
    ->ArgNames({"cars", "window", "broker_nodelay"})
    ->Args({1, 16, 1})
    ->Args({4, 64, 1})
    ->Args({4, 64, 0})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// ---- latency ----

constexpr int kWarmup = 300;  // samples per path, not recorded

using bench::Sampler;

void BM_MqttFrameToLua(benchmark::State& state) {
  for (auto _ : state) {
    auto made = makeRig(state, 1, state.range(1) != 0);
    if (!made) return;
    Rig& rig = *made;
    // host B
    Fleet fleetB(rig.loop);
    RemoteCars remote(rig.loop, fleetB, *rig.clientB);
    // the bare path's two clients
    MqttClient rawPub(rig.loop, clientOptions(*rig.broker, "bench-raw-pub"));
    MqttClient rawSub(rig.loop, clientOptions(*rig.broker, "bench-raw-sub"));
    // no answer within 10 s: a sample got lost
    Sampler sampler(rig.loop, kWarmup, {10s, true});
    rawSub.subscribe("bench/raw", 0);
    rawSub.onMessage = [&](std::string_view, std::string_view payload, bool) {
      if (payload.size() >= 3)
        sampler.arrived(std::atoi(std::string(payload.substr(0, 3)).c_str()));
    };
    if (!rig.connect(*rig.clientA) || !rig.connect(rawPub) || !rig.connect(rawSub) ||
        !rig.startRemote(remote, 1)) {
      state.SkipWithError(rig.error.c_str());
      return;
    }
    if (fleetB.cars().size() != 1) {
      state.SkipWithError("host B has not exactly one car");
      return;
    }
    auto host = std::make_unique<ScriptHost>(rig.loop, fleetB, nullptr, HostOptions{});
    if (auto e = bench::startMarking(*host, sampler, "mqtt_bench"); !e.empty()) {
      state.SkipWithError(e.c_str());
      return;
    }
    testing::runFor(rig.loop, 20ms);

    // The raw payload: as long as the bridge's E/frame payload, the location in its first 3 chars.
    std::string rawPayload =
        topics::frameEvent("e00000000001", rig.frame.span(), 1763726400000).payload;
    sampler.add("raw", [&](std::uint8_t location) {
      char head[4];
      std::snprintf(head, sizeof head, "%03u", location);
      std::copy(head, head + 3, rawPayload.begin());
      rawPub.publish("bench/raw", rawPayload, 0, false);
    });
    sampler.add("eng", [&](std::uint8_t location) { rig.inject(0, location); });
    bool ok = sampler.run(static_cast<int>(state.range(0)));
    if (!ok || host->errorCount() > 0) {
      state.SkipWithError(!ok ? "a sample got lost (no answer in 10 s)"
                              : "the Lua handler raised an error");
      return;
    }
    auto stats = sampler.report(state);
    state.SetIterationTime(stats[1].p50 * 1e-6);  // eng
  }
}
BENCHMARK(BM_MqttFrameToLua)
    ->ArgNames({"samples", "broker_nodelay"})
    ->Args({2000, 1})
    ->Args({2000, 0})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace

// BM_IntentManyKeys/<kind>: topics::parseIntent on a 64 KiB payload (the default
// --mqtt-max-payload) that anyone on the broker may send before any rate limit applies: kind 0
// one long string value (the floor: the parser's bytes alone), kind 1 thousands of distinct keys
// (the adversary: a parser that finds keys by a linear search pays quadratic time here).
// Report the ratio kind 1 / kind 0 (docs/performance.md "MQTT").
namespace {
std::string manyKeysPayload(bool keys) {
  const std::size_t size = pitwall::topics::kDefaultMaxPayload - 20;
  if (!keys) return R"({"pad":")" + std::string(size, 'x') + R"("})";
  std::string payload = "{";
  for (int i = 0; payload.size() < size; ++i)
    payload += (i ? "," : "") + std::string("\"") + std::to_string(i) + "\":0";
  return payload + "}";
}
}  // namespace

void BM_IntentManyKeys(benchmark::State& state) {
  const std::string payload = manyKeysPayload(state.range(0) == 1);
  const std::vector<std::string> cars{"e85a0f112233"};
  for (auto _ : state) {
    auto r = pitwall::topics::parseIntent("pit1", "Anki/Car/I", payload, cars);
    benchmark::DoNotOptimize(r);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(payload.size()));
}
BENCHMARK(BM_IntentManyKeys)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
