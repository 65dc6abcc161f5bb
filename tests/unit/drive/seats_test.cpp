// Human seats against the simulator (engine/drive/seats.hpp): who may hold which seat, what a
// holder may ask for, and that a car whose holder lets go or falls silent is slowed to a stop by
// the engine itself — no driver commands it here, the tests only say `driving()` as the human
// driver does — when the car is the seat's, and left alone when someone else drives it.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "engine/drive/seats.hpp"
#include "engine/fleet/fleet.hpp"
#include "engine/sim/grid.hpp"
#include "engine/sim/world.hpp"
#include "tests/support/sim_cars.hpp"

using namespace pitwall;

namespace {

struct Run {
  Loop loop{ClockKind::Virtual};
  sim::World world{loop, sim::namedLayout("oval").value(), 1};
  Fleet fleet{loop};
  drive::Seats seats{loop, fleet, 2};
  AnkiCar* cars[2] = {};
  Run() {
    for (int i = 0; i < 2; ++i)
      cars[i] = &testing::addSimulatedCar(loop, fleet, world, sim::gridSpec(world.track(), i));
    run(0.5);
    for (auto* c : cars) REQUIRE(c->sdkMode(true));
  }
  void run(double seconds) {
    loop.at(loop.now() + fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
  // Drives car `i` at `speed` as a driver would when its seat says so.
  void drive(int i, int speed) { REQUIRE(cars[i]->setSpeed(speed, 2000)); }
  // phone#1 holds seat 1 and phone#2 seat 2; both cars driven at `speed`.
  void twoPhonesDriving(int speed) {
    REQUIRE(seats.claim("phone#1", drive::Holder::Phone, 1));
    REQUIRE(seats.claim("phone#2", drive::Holder::Phone, 2));
    drive(0, speed);
    drive(1, speed);
  }
  // Both phones talk (throttle `throttle`) for `seconds` while a driver says it drives from
  // seats `from`..`to`; then both phones go.
  void phonesTalkThenGo(double seconds, int from, int to, double throttle = 0.5) {
    runDriving(seconds, from, to, [&] {
      REQUIRE(seats.input("phone#1", throttle, 0));
      REQUIRE(seats.input("phone#2", throttle, 0));
    });
    seats.release("phone#1", "the phone disconnected");
    seats.release("phone#2", "the phone disconnected");
  }
  // Runs `seconds`, with a driver saying every 0.1 s that it drives from seats `from`..`to`
  // (what the human driver does at every update).
  void runDriving(double seconds, int from = 1, int to = 2,
                  const std::function<void()>& each = {}) {
    for (int k = 0; k < static_cast<int>(seconds * 10 + 0.5); ++k) {
      for (int n = from; n <= to; ++n) seats.driving(n);
      if (each) each();
      run(0.1);
    }
  }
  // The simulator's truth: how fast car i really goes (mm/s).
  double speed(int i) { return world.cars()[static_cast<std::size_t>(i)]->truth().speed_mm_s; }
};

}  // namespace

TEST_CASE("seats: one holder a seat; a held seat cannot be taken; 0 takes the first free") {
  Run r;
  auto a = r.seats.claim("phone#1", drive::Holder::Phone, 1, "Anna");
  REQUIRE(a);
  CHECK(*a == 1);
  auto b = r.seats.claim("phone#2", drive::Holder::Phone, 1, "Ben");
  REQUIRE_FALSE(b);
  CHECK(b.error().find("seat 1 is held by another phone (Anna)") != std::string::npos);
  auto any = r.seats.claim("phone#2", drive::Holder::Phone, 0, "Ben");
  REQUIRE(any);
  CHECK(*any == 2);
  auto none = r.seats.claim("pad", drive::Holder::Gamepad, 0);
  REQUIRE_FALSE(none);
  CHECK(none.error().find("every seat is taken (2)") != std::string::npos);
  auto bad = r.seats.claim("pad", drive::Holder::Gamepad, 3);
  REQUIRE_FALSE(bad);
  CHECK(bad.error().find("there is no seat 3: this run has seats 1..2") != std::string::npos);
  CHECK(r.seats.claim("pad", drive::Holder::Gamepad, -1).error().find("no seat -1") !=
        std::string::npos);
  // asking again for one's own seat keeps it; a holder that moves frees the one it had
  CHECK(*r.seats.claim("phone#1", drive::Holder::Phone, 1) == 1);
  r.seats.release("phone#2", "left");
  CHECK(*r.seats.claim("phone#1", drive::Holder::Phone, 2) == 2);
  CHECK_FALSE(r.seats.seat(1)->held());
  CHECK(r.seats.heldBy("phone#1")->number == 2);
}

TEST_CASE("seats: no seats: driving is off, and the error says how to turn it on") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};
  drive::Seats seats{loop, fleet, 0};
  auto c = seats.claim("phone#1", drive::Holder::Phone);
  REQUIRE_FALSE(c);
  CHECK(c.error().find("--humans N") != std::string::npos);
}

TEST_CASE("seats: hostile input is refused with the value, and changes nothing") {
  Run r;
  REQUIRE(r.seats.claim("phone#1", drive::Holder::Phone, 1));
  REQUIRE(r.seats.input("phone#1", 0.5, 1));
  const double bad[] = {-0.01,
                        1.0001,
                        1e308,
                        -1e308,
                        std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::quiet_NaN()};
  for (double v : bad) {
    auto in = r.seats.input("phone#1", v, 0);
    REQUIRE_FALSE(in);
    CHECK(in.error().find("out of range: give 0 (stop) to 1 (full)") != std::string::npos);
  }
  CHECK(r.seats.input("phone#1", 0.5, 2).error().find("lane step 2") != std::string::npos);
  CHECK(r.seats.input("phone#1", 0.5, -7).error().find("lane step -7") != std::string::npos);
  CHECK(r.seats.input("nobody", 0.5, 0).error().find("take one first") != std::string::npos);
  CHECK(r.seats.seat(1)->throttle == 0.5);
  // lane steps add up, at most three either way, and are taken once
  for (int i = 0; i < 10; ++i) REQUIRE(r.seats.input("phone#1", 0.5, -1));
  CHECK(r.seats.takeLanes(1) == -3);
  CHECK(r.seats.takeLanes(1) == 0);
}

TEST_CASE("seats: a phone silent for 1 s loses its input and its car is slowed to a stop") {
  Run r;
  r.twoPhonesDriving(800);
  // phone 2 keeps talking every 0.1 s; phone 1 says one thing and then nothing
  REQUIRE(r.seats.input("phone#1", 0.8, 0));
  r.runDriving(3, 1, 2, [&] { REQUIRE(r.seats.input("phone#2", 0.8, 0)); });
  CHECK_FALSE(r.seats.seat(1)->live);
  CHECK(r.seats.seat(1)->held());  // still its phone's: input again makes it live
  CHECK(r.seats.seat(1)->throttle == 0);
  CHECK(r.cars[0]->state().target_speed_mm_s == 0);
  CHECK(r.speed(0) == 0);
  CHECK(r.seats.seat(2)->live);
  CHECK(r.speed(1) > 700);  // the other car drives on
  REQUIRE(r.seats.input("phone#1", 0.3, 0));
  CHECK(r.seats.seat(1)->live);
}

TEST_CASE("seats: a holder that lets go stops its car, however it was driven") {
  Run r;
  REQUIRE(r.seats.claim("pad", drive::Holder::Gamepad, 1));
  r.drive(0, 900);
  r.runDriving(3);  // a gamepad holds its throttle without sending: no silence for it
  CHECK(r.seats.seat(1)->live);
  CHECK(r.speed(0) > 800);
  r.seats.release("pad", "the gamepad was unplugged");
  CHECK_FALSE(r.seats.seat(1)->held());
  r.run(1.5);
  CHECK(r.speed(0) == 0);
}

TEST_CASE("seats: no live phone, no timer: a virtual run is not kept going by the seats") {
  Loop loop{ClockKind::Virtual};
  Fleet fleet{loop};  // no cars: the only timers are the seats'
  drive::Seats seats{loop, fleet, 2};
  REQUIRE(seats.claim("phone#1", drive::Holder::Phone, 1));
  CHECK(loop.pendingTimers() == 1);  // the silence timer
  REQUIRE(seats.claim("pad", drive::Holder::Gamepad, 2));
  CHECK(loop.pendingTimers() == 1);  // still one: a gamepad has none
  seats.release("phone#1", "left");
  CHECK(loop.pendingTimers() == 0);
  REQUIRE(seats.claim("phone#1", drive::Holder::Phone, 1));
  loop.run();  // ends: the phone falls silent after 1 s and nothing is left to wait for
  CHECK(loop.seconds() == doctest::Approx(1.0));
  CHECK_FALSE(seats.seat(1)->live);
  CHECK(loop.pendingTimers() == 0);
}

TEST_CASE("seats: `asked` tells each new throttle and lane step, not a repeat") {
  Run r;
  int asked = 0, changed = 0;
  auto a = r.seats.asked.connect([&](const drive::Seat&) { ++asked; });
  auto c = r.seats.changed.connect([&](const drive::Seat&) { ++changed; });
  REQUIRE(r.seats.claim("pad", drive::Holder::Gamepad, 1));
  CHECK(changed == 1);
  REQUIRE(r.seats.input("pad", 0.5, 0));
  REQUIRE(r.seats.input("pad", 0.5, 0));  // the heartbeat of a phone: nothing new
  CHECK(asked == 1);
  REQUIRE(r.seats.input("pad", 0.5, 1));
  REQUIRE(r.seats.input("pad", 0.25, 0));
  CHECK(asked == 3);
  CHECK(changed == 1);
}

TEST_CASE("seats: a loss leaves alone a car that no driver drives from the seat") {
  // The race director drives the scan lap and the grid itself, an AI may drive a seat no one
  // took: a phone that goes then must not stop a car that is not its to drive.
  Run r;
  r.twoPhonesDriving(700);
  r.phonesTalkThenGo(1.5, 2, 2);  // only seat 2's car is driven from its seat
  r.run(1.5);
  CHECK(r.cars[0]->state().target_speed_mm_s == 700);
  CHECK(r.speed(0) > 600);
  CHECK(r.cars[1]->state().target_speed_mm_s == 0);
  CHECK(r.speed(1) == 0);
}

TEST_CASE("seats: seats that go while held stop the cars driven from them") {
  Run r;
  auto own = std::make_unique<drive::Seats>(r.loop, r.fleet, 1);  // a script's own, say
  REQUIRE(own->claim("script#1", drive::Holder::Script, 1));
  REQUIRE(own->input("script#1", 1, 0));
  r.drive(0, 900);
  own->driving(1);
  r.run(0.5);
  own.reset();  // its version reloaded away
  r.run(1.5);
  CHECK(r.cars[0]->state().target_speed_mm_s == 0);
  CHECK(r.speed(0) == 0);
}

TEST_CASE("seats: a holder moving to another seat lets go of its old one after it took the new") {
  Run r;
  REQUIRE(r.seats.claim("phone#1", drive::Holder::Phone, 1));
  std::vector<std::string> seen;
  auto sub = r.seats.changed.connect([&](const drive::Seat& s) {
    seen.push_back(std::to_string(s.number) + (s.held() ? " held" : " free"));
    // someone waiting for a free seat takes it the moment it frees
    if (!s.held()) CHECK(r.seats.claim("pad", drive::Holder::Gamepad, 0));
  });
  REQUIRE(*r.seats.claim("phone#1", drive::Holder::Phone, 2) == 2);
  CHECK(seen == std::vector<std::string>{"2 held", "1 free", "1 held"});
  CHECK(r.seats.heldBy("phone#1")->number == 2);
  CHECK(r.seats.heldBy("pad")->number == 1);
}

TEST_CASE("seats: a car still at the speed its seat's driver gave is stopped, however long ago") {
  // the driver stopped saying so (a reload's pause, a director that fails, a long period), but
  // nothing else has commanded the car since: the speed it runs at is the seat's
  Run r;
  r.twoPhonesDriving(800);
  r.seats.driving(1);
  r.seats.driving(2);
  r.drive(1, 500);  // car 2: someone else (the director's cool-down, say) commands it after
  r.phonesTalkThenGo(3, 1, 0, 0.8);  // no driver says anything for 3 s; the phones still talk
  r.run(1.5);
  CHECK(r.cars[0]->state().target_speed_mm_s == 0);
  CHECK(r.speed(0) == 0);
  CHECK(r.cars[1]->state().target_speed_mm_s == 500);  // left to whoever commanded it last
}
