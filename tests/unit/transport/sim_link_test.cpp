#include "engine/transport/sim_link.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <vector>

#include "engine/protocol/anki/codec.hpp"

using namespace pitwall;
using namespace pitwall::sim;
using namespace std::chrono_literals;

namespace {

struct Rig {
  Loop loop{ClockKind::Virtual};
  World world{loop, namedLayout("oval").value(), 3};
  SimCar& car = world.addCar({.name = "car", .identifier = 0x00c0ffee});
  std::unique_ptr<SimLink> link = std::make_unique<SimLink>(loop, car, 20ms);
  std::vector<std::pair<TimePoint, anki::Message>> frames;
  std::vector<std::pair<TimePoint, std::string>> states;

  Rig() {
    link->onFrame([this](std::span<const std::uint8_t> f) {
      frames.emplace_back(loop.now(), anki::decode(f).value());
    });
    link->onState([this](bool up, const std::string& why) {
      states.emplace_back(loop.now(), (up ? "up: " : "down: ") + why);
    });
  }
  void send(const anki::Message& m) { CHECK(link->send(anki::encode(m).span())); }
  void runUntil(Duration t) {
    loop.at(t, [this] { loop.stop(); });
    loop.run();
  }
};

}  // namespace

TEST_CASE("connecting a sim link reports the connection on the loop") {
  Rig rig;
  CHECK_FALSE(rig.link->connected());
  rig.link->connect();
  CHECK(rig.link->connected());
  CHECK(rig.states.empty());  // reported from the loop, not from inside connect()
  rig.runUntil(100ms);
  REQUIRE(rig.states.size() == 1);
  CHECK(rig.states[0] == std::pair<TimePoint, std::string>{0ms, "up: connected"});
  CHECK(rig.car.truth().connected);
  // The car's status, sent on connect, arrives one latency later.
  REQUIRE(rig.frames.size() == 1);
  CHECK(rig.frames[0].first == 20ms);
  CHECK(std::holds_alternative<anki::CarStatus>(rig.frames[0].second));
}

TEST_CASE("frames cross the sim link after its latency each way, in order") {
  Rig rig;
  rig.link->connect();
  rig.runUntil(50ms);
  rig.frames.clear();
  rig.send(anki::PingRequest{});
  rig.send(anki::VersionRequest{});
  rig.loop.at(55ms, [&] { rig.send(anki::BatteryRequest{}); });
  rig.runUntil(200ms);
  REQUIRE(rig.frames.size() == 3);
  // Requests reach the car at 70 and 75 ms; answers come back 20 ms later.
  CHECK(rig.frames[0].first == 90ms);
  CHECK(std::holds_alternative<anki::PingResponse>(rig.frames[0].second));
  CHECK(rig.frames[1].first == 90ms);
  CHECK(std::holds_alternative<anki::VersionResponse>(rig.frames[1].second));
  CHECK(rig.frames[2].first == 95ms);
  CHECK(std::holds_alternative<anki::BatteryResponse>(rig.frames[2].second));
}

TEST_CASE("a car driven through a sim link reports positions") {
  Rig rig;
  rig.link->connect();
  rig.send(anki::SdkMode{true, 1});
  rig.send(anki::SetSpeed{600, 25000});
  rig.runUntil(2s);
  int positions = 0;
  for (auto& [t, m] : rig.frames) positions += std::holds_alternative<anki::PositionUpdate>(m);
  CHECK(positions >= 6);
  CHECK(rig.car.truth().speed_mm_s == 600);
}

TEST_CASE("a sim link sends nothing while it is not connected") {
  Rig rig;
  auto frame = anki::encode(anki::PingRequest{});
  CHECK_FALSE(rig.link->send(frame.span()));
  rig.runUntil(100ms);
  CHECK(rig.frames.empty());
}

TEST_CASE("disconnecting a sim link tells the car, which stops") {
  Rig rig;
  rig.link->connect();
  rig.send(anki::SdkMode{true, 1});
  rig.send(anki::SetSpeed{600, 25000});
  rig.runUntil(1s);
  rig.link->disconnect();
  CHECK_FALSE(rig.link->connected());
  CHECK_FALSE(rig.car.truth().connected);
  auto heard = rig.frames.size();
  rig.runUntil(2s);
  CHECK(rig.car.truth().speed_mm_s == 0);
  CHECK(rig.frames.size() == heard);
  REQUIRE(rig.states.size() == 2);
  CHECK(rig.states[1].second == "down: disconnected by the controller");
  CHECK_FALSE(rig.link->send(anki::encode(anki::PingRequest{}).span()));
}

TEST_CASE("a disconnect frame makes the car drop the sim link") {
  Rig rig;
  rig.link->connect();
  rig.send(anki::Disconnect{});
  rig.runUntil(100ms);
  CHECK_FALSE(rig.link->connected());
  REQUIRE(rig.states.size() == 2);
  CHECK(rig.states[1] == std::pair<TimePoint, std::string>{20ms, "down: the car disconnected"});
  // It can connect again.
  rig.link->connect();
  rig.send(anki::PingRequest{});
  rig.runUntil(200ms);
  CHECK(rig.link->connected());
  CHECK(std::holds_alternative<anki::PingResponse>(rig.frames.back().second));
}

TEST_CASE("a car that resets drops the sim link and is connected again once it can be") {
  Rig rig;
  rig.link->connect();
  rig.send(anki::SdkMode{true, 1});
  rig.send(anki::SetSpeed{600, 1000});
  rig.runUntil(1s);
  CHECK(rig.car.truth().sdk_mode);
  rig.car.reboot(3s);  // at 1 s: back from 4 s
  CHECK(rig.car.truth().speed_mm_s == 0);
  CHECK_FALSE(rig.car.truth().sdk_mode);
  rig.runUntil(3900ms);
  CHECK_FALSE(rig.link->connected());  // looked every 0.5 s: not yet
  rig.runUntil(5s);
  CHECK(rig.link->connected());
  REQUIRE(rig.states.size() == 3);
  CHECK(rig.states[1].second == "down: the car disconnected");
  CHECK(rig.states[2].second == "up: connected");
  CHECK(rig.states[2].first >= 4s);
  CHECK(rig.states[2].first <= 4500ms);
  // The controller's own disconnect stays down.
  rig.link->disconnect();
  rig.runUntil(8s);
  CHECK_FALSE(rig.link->connected());
}

TEST_CASE("destroying a sim link makes its pending callbacks no-ops and stops the car") {
  Rig rig;
  bool called = false;
  rig.link->onFrame([&](std::span<const std::uint8_t>) { called = true; });
  rig.link->onState([&](bool, const std::string&) { called = true; });
  rig.link->connect();
  rig.send(anki::SdkMode{true, 1});
  rig.send(anki::SetSpeed{600, 25000});
  rig.send(anki::PingRequest{});
  rig.link.reset();  // a state report is posted, frames are in flight both ways
  rig.runUntil(1s);
  CHECK_FALSE(called);
  CHECK_FALSE(rig.car.truth().connected);
  CHECK(rig.car.truth().speed_mm_s == 0);
}

TEST_CASE("a world destroyed before its sim link leaves the link disconnected") {
  Loop loop(ClockKind::Virtual);
  auto world = std::make_unique<World>(loop, namedLayout("oval").value(), 1);
  SimLink link(loop, world->addCar({}), 5ms);
  std::vector<std::string> states;
  link.onState([&](bool, const std::string& why) { states.push_back(why); });
  link.connect();
  world.reset();
  CHECK_FALSE(link.connected());
  loop.run();
  CHECK(states == std::vector<std::string>{"connected", "the car disconnected"});
}

TEST_CASE("a sim link names the car by its identifier") {
  Rig rig;
  CHECK(rig.link->address() == "sim:00c0ffee");
}

// docs/simulator.md "Timing": a frame waits for the link's next connection event.
TEST_CASE("with a connection interval, frames wait for the next event, in order, spread over it") {
  Rig rig;
  rig.link->setConnectionInterval(30ms);
  const Duration phase(0x00c0ffee % 30'000'000);  // the car's identifier, in ns, modulo 30 ms
  rig.link->connect();
  rig.runUntil(100ms);
  rig.frames.clear();
  // a ping every 7 ms: each reaches the car at its next event after 20 ms, and the answer the
  // event after 20 ms more
  std::vector<TimePoint> sent;
  for (int i = 0; i < 30; ++i)
    rig.loop.at(100ms + i * 7ms, [&] {
      sent.push_back(rig.loop.now());
      rig.send(anki::PingRequest{});
    });
  rig.runUntil(600ms);
  REQUIRE(rig.frames.size() == 30);
  Duration least = 1s, most{};
  for (std::size_t i = 0; i < rig.frames.size(); ++i) {
    const TimePoint at = rig.frames[i].first;
    CHECK((at - phase).count() % 30'000'000 == 0);    // on a connection event
    if (i > 0) CHECK(at >= rig.frames[i - 1].first);  // never overtakes
    const Duration delay = at - sent[i];
    least = std::min(least, delay);
    most = std::max(most, delay);
  }
  CHECK(least >= 40ms);         // the two latencies at least
  CHECK(most <= 40ms + 60ms);   // and at most an interval more each way
  CHECK(most - least >= 20ms);  // spread: tens of ms, as a real connection's
}

TEST_CASE("a real-time sim link has the connection interval; a virtual-time one has none") {
  Loop real{ClockKind::Real};
  World realWorld{real, namedLayout("oval").value(), 3};
  SimLink realLink(real, realWorld.addCar({.name = "a"}));
  CHECK(realLink.connectionInterval() == SimLink::kRealTimeInterval);
  Rig rig;
  CHECK(rig.link->connectionInterval() == Duration::zero());
}
