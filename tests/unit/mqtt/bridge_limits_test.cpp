// MqttBridge against hostile and excessive input (docs/mqtt.md "Hostile input"): hostile intents,
// floods of intents and of bad intents, and the stop that no rate limit holds back.
#include "tests/unit/mqtt/bridge_fixture.hpp"

#include <doctest/doctest.h>

using namespace pitwall;
using namespace pitwall::testing::bridge;
using namespace std::chrono_literals;
using pitwall::testing::hostilePayloads;
using pitwall::testing::MosquittoBroker;
using pitwall::testing::runFor;
using pitwall::testing::runUntil;

TEST_CASE("mqtt bridge: a hostile intent is refused with a short error and the car still obeys") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  // Every refusal answered and every intent executed: the rate limits have a test of their own.
  auto options = optionsFor(kHost);
  options.intents = options.errors = RateLimit{1000, 1000};
  Host h(loop, broker, options);
  waitForCars(loop, o, h);
  const std::string one = h.carTopic(0, "I");
  int speed = 100;
  // The bridge is alive and the car obeys: a valid intent after each hostile one is executed.
  auto obeys = [&] {
    ++speed;
    o.send(one, R"({"type":"speed","speed":)" + std::to_string(speed) + R"(,"acceleration":1000})");
    return runUntil(loop, [&] {
      auto sent = h.sent<anki::SetSpeed>(0);
      return !sent.empty() && sent.back().speed_mm_s == speed;
    });
  };

  std::size_t errors = 0;
  for (const auto& bad : hostilePayloads()) {
    CAPTURE(bad.name);
    std::size_t frames = h.tx.size();
    o.send(one, bad.payload);
    REQUIRE(runUntil(loop, [&] { return o.count(kIntentError) == errors + 1; }));
    ++errors;
    const auto& answer = o.last(kIntentError)->payload;
    CHECK(answer.size() <= topics::kMaxIntentError);
    auto j = Json::parse(answer);  // valid JSON, valid UTF-8
    CHECK(j["topic"] == one);
    auto error = j["error"].get<std::string>();
    CAPTURE(error);
    CHECK(error.find(bad.error) != std::string::npos);
    // at most 80 bytes of the payload (escaped: at most 4 bytes each), plus our words
    CHECK(error.size() < 600);
    CHECK(h.tx.size() == frames);  // nothing was sent to a car
    CHECK(obeys());
  }
  // Invalid bytes are shown escaped, as \xNN.
  auto utf8 = Json::parse(o.on(kIntentError)[4]->payload)["error"].get<std::string>();
  CHECK(utf8.find("\\xff") != std::string::npos);

  // On the limits, not beyond them: executed.
  o.send(one, pitwall::testing::paddedSpeedIntent(64 * 1024, 1234));
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1234; }));
  o.send(one, pitwall::testing::deepSpeedIntent(64, 1235));
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1235; }));

  // An empty payload clears a retained message: ignored without an answer.
  o.send(one, "");
  CHECK(obeys());
  // What the bridge reads of other hosts (their cars and status) is read with the same care.
  for (const auto& bad : hostilePayloads()) {
    o.send("Anki/Host/pit9/S/Cars", bad.payload);
    o.send("Anki/Host/pit9/S/HostStatus", bad.payload);
  }
  CHECK(obeys());
  CHECK(o.count(kIntentError) == errors);
  CHECK(h.bridge->stats().faults == 0);
  CHECK(h.bridge->stats().rejected == errors);
}

TEST_CASE("mqtt bridge: a flood of intents to a car is cut to its rate, with one error a second") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker);  // the default limits: 50 intents a second per car, 20 at once
  waitForCars(loop, o, h);
  const std::string one = h.carTopic(0, "I");
  const RateLimit limit = h.bridgeOptions.intents;
  CHECK(limit.perSecond == 50);
  CHECK(limit.burst == 20);

  constexpr int kFlood = 1000;
  auto start = loop.now();
  for (int i = 0; i < kFlood; ++i)
    o.send(one,
           R"({"type":"speed","speed":)" + std::to_string(i % 1500) + R"(,"acceleration":1000})");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.intents + stats.throttled == kFlood; }, 20s));
  double seconds = toSeconds(loop.now() - start);
  CAPTURE(seconds);
  auto executed = h.sent<anki::SetSpeed>(0).size();
  CHECK(executed == stats.intents);
  CHECK(executed <= limit.burst + limit.perSecond * seconds + 1);
  CHECK(stats.throttled > 0);
  CHECK(h.sent<anki::SetSpeed>(1).empty());

  // Every dropped intent is accounted for, in at most one error a second (the first at once).
  auto droppedIn = [&] {
    std::uint64_t n = 0;
    for (const auto* m : o.on(kIntentError)) {
      auto error = Json::parse(m->payload)["error"].get<std::string>();
      CHECK(error.find(" for car " + h.id(0) + " w") != std::string::npos);
      CHECK(error.find("at most 50 a second, 20 at once") != std::string::npos);
      n += std::stoull(error);
    }
    return n;
  };
  REQUIRE(runUntil(loop, [&] { return droppedIn() == stats.throttled; }));
  seconds = toSeconds(loop.now() - start);
  CHECK(o.count(kIntentError) >= 1);
  CHECK(o.count(kIntentError) <= 2 + seconds);
  CHECK(Json::parse(o.last(kIntentError)->payload)["topic"] == one);

  // The bucket refills at 50 a second: after 50 ms, the car obeys again.
  runFor(loop, 50ms);
  o.send(one, R"({"type":"speed","speed":1499,"acceleration":1000})");
  REQUIRE(runUntil(loop, [&] { return h.sent<anki::SetSpeed>(0).back().speed_mm_s == 1499; }));
}

TEST_CASE_FIXTURE(Bridged,
                  "mqtt bridge: a stop is never throttled, however full the flood before it") {
  const std::string one = h.carTopic(0, "I");
  constexpr int kFlood = 300;
  for (int i = 0; i < kFlood; ++i)
    o.send(one, R"({"type":"speed","speed":800,"acceleration":1000})");
  o.send(one, R"({"type":"speed","speed":0,"acceleration":12500})");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.intents + stats.throttled == kFlood + 1; }, 20s));
  CHECK(stats.throttled > 0);  // the bucket was empty when the stop came
  auto speeds = h.sent<anki::SetSpeed>(0);
  REQUIRE_FALSE(speeds.empty());
  CHECK(speeds.back().speed_mm_s == 0);
}

TEST_CASE("mqtt bridge: a flood of bad intents gets a bounded number of answers") {
  MosquittoBroker broker;
  Loop loop(ClockKind::Real);
  Observer o(loop, broker);
  REQUIRE(runUntil(loop, [&] { return o.connects == 1; }));
  Host h(loop, broker);  // the default: 10 answers a second, 20 at once
  waitForCars(loop, o, h);
  constexpr int kFlood = 500;
  auto start = loop.now();
  for (int i = 0; i < kFlood; ++i) o.send("Anki/Car/nobody" + std::to_string(i) + "/I", "[1]");
  const auto& stats = h.bridge->stats();
  REQUIRE(runUntil(
      loop, [&] { return stats.rejected == kFlood; }, 20s));
  // Every refusal is either answered or counted in a summary.
  auto accounted = [&] {
    std::uint64_t n = 0;
    for (const auto* m : o.on(kIntentError)) {
      auto error = Json::parse(m->payload)["error"].get<std::string>();
      n += error.find("rejected without an answer each") != std::string::npos ? std::stoull(error)
                                                                              : 1;
    }
    return n;
  };
  REQUIRE(runUntil(loop, [&] { return accounted() == kFlood; }));
  double seconds = toSeconds(loop.now() - start);
  CAPTURE(seconds);
  CHECK(stats.unanswered > 0);
  CHECK(o.count(kIntentError) <= 20 + 10 * seconds + 2 + seconds);
  auto last = Json::parse(o.last(kIntentError)->payload)["error"].get<std::string>();
  CHECK(last.find("(S/IntentError answers at most 10 a second, 20 at once); the last: unknown "
                  "car \"nobody") != std::string::npos);
  // and the bridge carries on
  o.send(h.carTopic(0, "I"), R"({"type":"speed","speed":321,"acceleration":1000})");
  REQUIRE(runUntil(loop, [&] { return !h.sent<anki::SetSpeed>(0).empty(); }));
}
