// The race view costs the race nothing it can feel (docs/view.md): a received frame to a Lua
// onPosition handler while the view serves 5 browsers — 3 reading as fast as they can, 2 stalled
// (they handshake and never read again) — against the same path without a view.
//
// Both: a ScriptHost with a handler set from Lua, AnkiCar::receive(frame), and every 64 frames
// one poll of the loop's io_context (where the server accepts, paces and writes: at most 30
// updates a second to each browser; a running engine's loop waits on its sockets once for many
// handlers too, so the poll is shared as it is there). With the view, the feed (chained on the
// fleet's frames) follows the car on the oval too. Each iteration changes the location id.
// Report the ratio of the two (docs/performance.md); the feed alone, without browsers, shows
// what following the cars costs.
#include <benchmark/benchmark.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "bindings/script_host.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/track.hpp"
#include "engine/view/server.hpp"
#include "tests/bench/cpu_clock.hpp"
#include "tests/bench/frames.hpp"

namespace {

using namespace pitwall;
using bench::BenchLink;
using bench::kLocationByte;
using bench::positionFrame;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

constexpr const char* kHandler =
    "pitwall.cars()[1].onPosition = function(car, ev)\n"
    "  local p, l, s = ev.piece, ev.location, ev.speed\n"
    "end\n";

// A browser in a thread of its own: reads every update until told to stop, or stalls.
struct Browser {
  asio::io_context io;
  websocket::stream<tcp::socket> ws{io};
  std::atomic<bool> ready{false}, stop{false};
  std::atomic<long> updates{0};
  std::thread thread;
  Browser(std::uint16_t port, bool reads) {
    thread = std::thread([this, port, reads] {
      try {
        ws.next_layer().connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
        ws.next_layer().set_option(asio::socket_base::receive_buffer_size(4096));
        ws.handshake("127.0.0.1", "/ws");
        ready = true;
        if (!reads) {
          while (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(5));
          return;
        }
        beast::flat_buffer b;
        while (!stop) {
          ws.read(b);
          b.consume(b.size());
          ++updates;
        }
      } catch (...) {
        ready = true;  // closed by the server (a stalled browser, the end of the benchmark)
      }
    });
  }
  ~Browser() {
    stop = true;
    beast::error_code ec;
    ws.next_layer().shutdown(tcp::socket::shutdown_both, ec);
    thread.join();
  }
};

struct Rig {
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  AnkiCar& car;
  std::unique_ptr<view::Feed> feed;
  std::unique_ptr<view::Server> server;
  std::unique_ptr<ScriptHost> host;
  std::vector<std::unique_ptr<Browser>> browsers;
  std::filesystem::path assets;
  std::string error;

  Rig(bool view, int readers, int stalled)
      : car(fleet.add(std::make_unique<BenchLink>(), CarIdentity{})) {
    // A real-time run's loop always has a timer pending (the simulator's tick, a race's): so
    // here, with or without the view, and a poll of the loop costs the same in both.
    loop.after(std::chrono::hours(1), [] {});
    if (view) {
      assets = std::filesystem::temp_directory_path() / "pitwall-view-bench";
      std::filesystem::create_directories(assets);
      std::ofstream(assets / "index.html") << "bench";
      feed = std::make_unique<view::Feed>(loop, fleet, "simulator");
      feed->setTrack(sim::namedLayout("oval").value(), "layout");
      view::ServerOptions o;
      o.assets = assets;
      server = std::make_unique<view::Server>(loop, *feed, o);
      if (auto started = server->start(); !started) {
        error = started.error();
        return;
      }
      for (int i = 0; i < readers + stalled; ++i)
        browsers.push_back(std::make_unique<Browser>(server->port(), i < readers));
      auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (server->clients() < browsers.size() && std::chrono::steady_clock::now() < until)
        loop.io().poll();
      if (server->clients() < browsers.size()) error = "the browsers did not connect";
    }
    HostOptions options;
    options.view = feed.get();
    host = std::make_unique<ScriptHost>(loop, fleet, nullptr, options);
    if (auto started = host->startString(kHandler, "bench"); !started) error = started.error();
  }
  ~Rig() {
    host.reset();
    browsers.clear();
    server.reset();
    feed.reset();
    if (!assets.empty()) std::filesystem::remove_all(assets);
  }
};

void frameToLua(benchmark::State& state, bool view, int readers, int stalled) {
  Rig rig(view, readers, stalled);
  if (!rig.error.empty()) {
    state.SkipWithError(rig.error.c_str());
    return;
  }
  anki::Frame frame = positionFrame();
  std::uint8_t location = 0;
  for (auto _ : state) {
    frame.bytes[kLocationByte] = location++;
    rig.car.receive(frame.span());
    if ((location & 63) == 0) rig.loop.io().poll();
  }
  if (rig.host->errorCount() > 0) state.SkipWithError("the Lua handler raised an error");
  long updates = 0;
  for (auto& b : rig.browsers) updates += b->updates;
  state.counters["browser_updates"] = static_cast<double>(updates);
  state.SetItemsProcessed(state.iterations());
}

// The floor: the same path and poll, no view.
void BM_FrameToLuaNoView(benchmark::State& state) {
  frameToLua(state, false, 0, 0);
}
BENCHMARK(BM_FrameToLuaNoView)->MinTime(1.0);

void BM_FrameToLuaView5Browsers(benchmark::State& state) {
  frameToLua(state, true, 3, 2);
}
BENCHMARK(BM_FrameToLuaView5Browsers)->MinTime(1.0);

// The feed alone (a view nobody watches).
void BM_FrameToLuaViewNoBrowser(benchmark::State& state) {
  frameToLua(state, true, 0, 0);
}
BENCHMARK(BM_FrameToLuaViewNoBrowser)->MinTime(1.0);

// What --view costs a frame when nobody watches, as a ratio measured in one run: the path with
// the feed (view_ns) and without it (floor_ns), interleaved in blocks of 16384 frames (a few
// milliseconds each: long enough that a block's first frames, which find the other rig's data in
// the caches, do not count; short enough that both see the same machine), each timed in this
// thread's CPU time (issue 35: ≤ 1.2×).
void BM_FrameToLuaViewRatio(benchmark::State& state) {
  using Clock = bench::ThreadCpuClock;
  constexpr int kBlock = 16384;
  Rig view(true, 0, 0);
  Rig floor(false, 0, 0);
  if (!view.error.empty() || !floor.error.empty()) {
    state.SkipWithError(!view.error.empty() ? view.error.c_str() : floor.error.c_str());
    return;
  }
  anki::Frame frame = positionFrame();
  std::uint8_t location = 0;
  Clock::duration viewTime{}, floorTime{};
  for (auto _ : state) {
    auto t0 = Clock::now();
    for (int i = 0; i < kBlock; ++i) {
      frame.bytes[kLocationByte] = location++;
      view.car.receive(frame.span());
      if ((location & 63) == 0) view.loop.io().poll();
    }
    auto t1 = Clock::now();
    for (int i = 0; i < kBlock; ++i) {
      frame.bytes[kLocationByte] = location++;
      floor.car.receive(frame.span());
      if ((location & 63) == 0) floor.loop.io().poll();
    }
    auto t2 = Clock::now();
    viewTime += t1 - t0;
    floorTime += t2 - t1;
  }
  if (view.host->errorCount() > 0 || floor.host->errorCount() > 0)
    state.SkipWithError("the Lua handler raised an error");
  const double events = static_cast<double>(state.iterations()) * kBlock;
  const double viewNs = std::chrono::duration<double, std::nano>(viewTime).count() / events;
  const double floorNs = std::chrono::duration<double, std::nano>(floorTime).count() / events;
  state.counters["view_ns"] = viewNs;
  state.counters["floor_ns"] = floorNs;
  state.counters["ratio"] = viewNs / floorNs;
}
BENCHMARK(BM_FrameToLuaViewRatio)->MinTime(2.0);

}  // namespace
