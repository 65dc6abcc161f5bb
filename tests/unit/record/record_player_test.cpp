#include "engine/record/record_player.hpp"

#include <doctest/doctest.h>

#include <cstdio>
#include <functional>
#include <sstream>

using namespace pitwall;
using namespace std::chrono_literals;

namespace {
// A record of `frames` ping responses from car 1, one a millisecond.
std::string pings(int frames) {
  std::string text;
  text.reserve(static_cast<std::size_t>(frames) * 48);
  char line[96];
  for (int i = 0; i < frames; ++i) {
    std::snprintf(line, sizeof line,
                  R"({"t":%.6f,"car":1,"dir":"rx","hex":"01 17"})"
                  "\n",
                  i / 1000.0);
    text += line;
  }
  return text;
}
}  // namespace

// A seek across many frames on the real clock is delivered in slices: the loop turns in between
// (a ticker of its own fires while the seek is under way, as the view's requests and the signals
// would be answered), and in the end every frame up to the target was delivered once.
TEST_CASE("record player: a long seek on the real clock lets the loop turn between slices") {
  // 25 slices of 4096 lines: enough for the loop to turn between them many times; the guard
  // below is a safety net only (the ASan build at -O0 delivers some 4000 frames a second
  // beside a loaded machine's other work)
  const int kFrames = 100000;
  std::istringstream scan(pings(kFrames));
  RecordSummary summary = scanRecord(scan);
  REQUIRE(summary.framesOut.size() == 1);
  std::istringstream in(pings(kFrames));
  Loop loop(ClockKind::Real);
  Fleet fleet(loop);
  RecordPlayer player(loop, fleet, in, summary);
  AnkiCar* car = player.car(1);
  REQUIRE(car != nullptr);
  int ticksDuringSeek = 0;
  bool seeking = false;
  std::function<void()> tick = [&] {
    if (seeking) ++ticksDuringSeek;
    loop.after(1ms, tick);
  };
  loop.after(1ms, tick);
  bool ended = false;
  player.onEnd = [&] {
    ended = true;
    seeking = false;
    loop.stop();
  };
  player.pause(true);
  loop.post([&] {
    seeking = true;
    player.seek(player.duration());
    CHECK(player.position() < player.duration());  // under way: as far as it has come
  });
  auto guard = loop.after(300s, [&] { loop.stop(); });
  loop.run();
  loop.cancel(guard);
  CHECK(ended);
  CHECK(car->state().frames_in == static_cast<std::uint64_t>(kFrames));
  CHECK(ticksDuringSeek > 0);
  CHECK(player.position() == doctest::Approx(player.duration()));
}

// A second seek while one is under way takes over: backwards, the cars start again from the
// record's start and reach the new target, each frame up to it delivered once after the rewind.
TEST_CASE("record player: a seek under way gives way to the next one") {
  const int kFrames = 400000;
  std::istringstream scan(pings(kFrames));
  RecordSummary summary = scanRecord(scan);
  std::istringstream in(pings(kFrames));
  Loop loop(ClockKind::Real);
  Fleet fleet(loop);
  RecordPlayer player(loop, fleet, in, summary);
  int rewinds = 0;
  player.onRewind = [&] { ++rewinds; };
  player.pause(true);
  loop.post([&] {
    player.seek(player.duration());
    loop.post([&] { player.seek(0.1); });  // behind the first slice (256 frames at least)
  });
  auto guard = loop.after(300s, [&] { loop.stop(); });  // a safety net, not a time limit
  // paused: once the seek is done the position stays at its target
  std::function<void()> poll = [&] {
    if (rewinds == 1 && player.position() == doctest::Approx(0.1).epsilon(1e-9)) return loop.stop();
    loop.after(1ms, poll);
  };
  loop.after(1ms, poll);
  loop.run();
  loop.cancel(guard);
  CHECK(rewinds == 1);
  CHECK(player.position() == doctest::Approx(0.1));
}

namespace {
// Two frames with `bad` bad lines between them (and after the last: the end is bad lines too).
std::string badRun(int bad) {
  std::string text = R"({"t":0.000000,"car":1,"dir":"rx","hex":"01 17"})"
                     "\n";
  text.reserve(static_cast<std::size_t>(bad) * 24 + 200);
  for (int i = 0; i < bad; ++i) text += "not a frame of a record\n";
  text += R"({"t":0.500000,"car":1,"dir":"rx","hex":"01 17"})"
          "\n";
  for (int i = 0; i < bad; ++i) text += "{\"t\": broken\n";
  return text;
}
}  // namespace

// The adversary: 200,000 bad lines in a row between two frames and after the last. The player
// reads them a few thousand at a time with the loop turning between (a ticker of its own fires
// meanwhile), both for a seek across them and for playback, and every frame is delivered once.
TEST_CASE("record player: a long run of bad lines is read with the loop turning") {
  const int kBad = 200000;  // about fifty reads
  const std::string text = badRun(kBad);
  std::istringstream scan(text);
  RecordSummary summary = scanRecord(scan);
  REQUIRE(summary.framesOut.size() == 1);

  // Plays `text` with a ticker of its own on the loop; `start` begins the playback or the seek.
  struct Outcome {
    bool ended = false;
    std::uint64_t frames = 0;
    int ticks = 0;
  };
  auto play = [&](const std::function<void(Loop&, RecordPlayer&)>& start) {
    std::istringstream in(text);
    Loop loop(ClockKind::Real);
    Fleet fleet(loop);
    RecordPlayer player(loop, fleet, in, summary);
    Outcome out;
    std::function<void()> tick = [&] {
      ++out.ticks;
      loop.after(1ms, tick);
    };
    loop.after(1ms, tick);
    player.onEnd = [&] {
      out.ended = true;
      loop.stop();
    };
    start(loop, player);
    auto guard = loop.after(300s, [&] { loop.stop(); });  // a safety net, not a time limit
    loop.run();
    loop.cancel(guard);
    out.frames = player.car(1)->state().frames_in;
    return out;
  };

  SUBCASE("a seek across them") {
    auto out = play([](Loop& loop, RecordPlayer& player) {
      player.pause(true);
      loop.post([&player] { player.seek(player.duration()); });
    });
    CHECK(out.ended);
    CHECK(out.frames == 2);
    CHECK(out.ticks > 2);  // the loop turned while the bad lines were read
  }
  SUBCASE("playback across them") {
    auto out = play([](Loop&, RecordPlayer& player) {
      player.setSpeed(100);  // the half second between the frames in 5 ms
      player.play();
    });
    CHECK(out.ended);
    CHECK(out.frames == 2);
    CHECK(out.ticks > 2);
  }
}

// A record's link lines play as the run's link went: the car drops (with the run's reason) and
// comes back, its health is what the run's link told; a seek back plays them again, not twice.
TEST_CASE("record player: a link line drops the replayed car and brings it back, with its health") {
  const std::string text =
      pings(10) +
      R"({"t":0.020000,"car":1,"link":{"up":false,"reason":"bluetoothd went away","writeFailures":2,"stalls":1,"rssi":-66}})"
      "\n"
      R"({"t":0.030000,"car":1,"link":{"up":true,"writeFailures":2,"stalls":1,"rssi":-60}})"
      "\n"
      R"({"t":0.040000,"car":1,"link":{"up":false,"reason":"the car rebooted"}})"
      "\n";
  std::istringstream scan(text);
  RecordSummary summary = scanRecord(scan);
  CHECK(summary.drops[1] == 2);
  std::istringstream in(text);
  Loop loop(ClockKind::Virtual);
  Fleet fleet(loop);
  RecordPlayer player(loop, fleet, in, summary);
  AnkiCar* car = player.car(1);
  REQUIRE(car != nullptr);
  auto settle = [&] {
    loop.after(1s, [&] { loop.stop(); });
    loop.run();
  };
  std::vector<std::string> seen;
  auto sub = car->connectionChanged.connect(
      [&](bool up, const std::string& reason) { seen.push_back(up ? "up" : "down: " + reason); });
  player.pause(true);
  player.seek(0.035);
  settle();
  CHECK(seen == std::vector<std::string>{"down: bluetoothd went away", "up"});
  CHECK(car->state().connected);
  CHECK(car->state().drops == 1);
  CHECK(car->state().connects == 2);
  CHECK(car->link().health().writeFailures == 2);
  CHECK(car->link().health().rssi == -60);
  player.seek(0.05);
  settle();
  CHECK_FALSE(car->state().connected);
  CHECK(car->state().last_drop == "the car rebooted");
  CHECK(car->state().drops == 2);
  player.seek(0.035);  // back: from the start again, each line once
  settle();
  CHECK(car->state().connected);
  CHECK(car->state().drops == 1);
  CHECK(car->state().connects == 2);
}
