#include "engine/core/signal.hpp"

#include <doctest/doctest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

using namespace pitwall;

TEST_CASE("signal: slots are called in the order they were connected, with the arguments") {
  Signal<int, const std::string&> s;
  std::vector<std::string> calls;
  auto a =
      s.connect([&](int n, const std::string& t) { calls.push_back("a" + t + std::to_string(n)); });
  auto b =
      s.connect([&](int n, const std::string& t) { calls.push_back("b" + t + std::to_string(n)); });
  s.emit(1, "x");
  s(2, "y");
  CHECK(calls == std::vector<std::string>{"ax1", "bx1", "ay2", "by2"});
  CHECK(s.size() == 2);
}

TEST_CASE("signal: a slot dies with its subscription") {
  Signal<> s;
  int calls = 0;
  auto keep = std::make_shared<int>(0);
  std::weak_ptr<int> captured = keep;
  {
    auto sub = s.connect([&calls, keep] { ++calls; });
    keep.reset();
    s.emit();
    CHECK(sub.connected());
    CHECK_FALSE(captured.expired());  // the slot holds its captures while subscribed
  }
  CHECK(captured.expired());  // and lets them go with the subscription
  s.emit();
  CHECK(calls == 1);
  CHECK(s.empty());
}

TEST_CASE("signal: disconnect() and moving a subscription") {
  Signal<> s;
  int calls = 0;
  Subscription sub = s.connect([&] { ++calls; });
  Subscription moved = std::move(sub);
  CHECK_FALSE(sub.connected());  // NOLINT: moved from on purpose
  CHECK(moved.connected());
  s.emit();
  CHECK(calls == 1);
  moved.disconnect();
  CHECK_FALSE(moved.connected());
  s.emit();
  CHECK(calls == 1);
  moved.disconnect();  // twice is harmless

  // Assigning over a subscription drops the slot it held.
  int other = 0;
  Subscription a = s.connect([&] { ++calls; });
  a = s.connect([&] { ++other; });
  s.emit();
  CHECK(calls == 1);
  CHECK(other == 1);
  CHECK(s.size() == 1);
}

TEST_CASE("signal: subscriptions may be destroyed in any order, before or after their signal") {
  int calls = 0;
  std::optional<Subscription> first, second, third;
  {
    Signal<int> s;
    first = s.connect([&](int) { ++calls; });
    second = s.connect([&](int) { ++calls; });
    third = s.connect([&](int) { ++calls; });
    second.reset();  // the middle one first
    s.emit(0);
    CHECK(calls == 2);
    first.reset();
    s.emit(0);
    CHECK(calls == 3);
    // the signal goes now, third still subscribed
  }
  CHECK_FALSE(third->connected());
  third->disconnect();  // no crash: nothing left to disconnect
  third.reset();
}

TEST_CASE("signal: a slot that disconnects itself during an emit finishes its call, once") {
  Signal<> s;
  std::vector<std::string> calls;
  Subscription self;
  self = s.connect([&, tag = std::string("self")] {
    self.disconnect();
    calls.push_back(tag);  // its captures are still alive here
  });
  auto after = s.connect([&] { calls.push_back("after"); });
  s.emit();
  s.emit();
  CHECK(calls == std::vector<std::string>{"self", "after", "after"});
}

TEST_CASE("signal: a slot disconnected by an earlier slot during an emit is not called") {
  Signal<> s;
  std::vector<std::string> calls;
  Subscription victim;
  auto killer = s.connect([&] {
    calls.push_back("killer");
    victim.disconnect();
  });
  victim = s.connect([&] { calls.push_back("victim"); });
  auto last = s.connect([&] { calls.push_back("last"); });
  s.emit();
  CHECK(calls == std::vector<std::string>{"killer", "last"});
  CHECK(s.size() == 2);
}

TEST_CASE("signal: a slot connected during an emit is called from the next emit on") {
  Signal<> s;
  std::vector<std::string> calls;
  std::vector<Subscription> added;
  auto adder = s.connect([&] {
    calls.push_back("adder");
    // enough slots to make the list grow while it is being walked
    for (int i = 0; i < 20; ++i) added.push_back(s.connect([&] { calls.push_back("new"); }));
  });
  s.emit();
  CHECK(calls == std::vector<std::string>{"adder"});
  calls.clear();
  adder.disconnect();
  s.emit();
  CHECK(calls.size() == 20);
}

TEST_CASE("signal: an emit inside an emit runs the slots connected at its own start") {
  Signal<int> s;
  std::vector<std::string> calls;
  Subscription late;
  auto outer = s.connect([&](int depth) {
    calls.push_back("outer" + std::to_string(depth));
    if (depth == 0) {
      late = s.connect([&](int d) { calls.push_back("late" + std::to_string(d)); });
      s.emit(1);
    }
  });
  auto second = s.connect([&](int depth) { calls.push_back("second" + std::to_string(depth)); });
  s.emit(0);
  // the inner emit started after `late` was connected: it calls it; the outer one does not
  CHECK(calls == std::vector<std::string>{"outer0", "outer1", "second1", "late1", "second0"});
}

TEST_CASE("signal: a slot removed inside a nested emit stays removed for the outer one") {
  Signal<int> s;
  std::vector<std::string> calls;
  Subscription b;
  auto a = s.connect([&](int depth) {
    calls.push_back("a" + std::to_string(depth));
    if (depth == 0) s.emit(1);
    if (depth == 1) b.disconnect();
  });
  b = s.connect([&](int depth) { calls.push_back("b" + std::to_string(depth)); });
  s.emit(0);
  CHECK(calls == std::vector<std::string>{"a0", "a1"});
  CHECK(s.size() == 1);
}

TEST_CASE("signal: a slot may destroy the signal it is called by") {
  auto s = std::make_unique<Signal<>>();
  std::vector<std::string> calls;
  auto first = s->connect([&] {
    calls.push_back("first");
    s.reset();
  });
  auto second = s->connect([&] { calls.push_back("second"); });
  s->emit();
  // The emit that was under way finishes with the slots it had (their owners still hold them).
  CHECK(calls == std::vector<std::string>{"first", "second"});
  CHECK_FALSE(first.connected());
  CHECK_FALSE(second.connected());
}

TEST_CASE("signal: a subscription may be destroyed by another slot while the emit runs") {
  Signal<> s;
  int calls = 0;
  auto owned = std::make_unique<Subscription>();
  auto dropper = s.connect([&] { owned.reset(); });
  *owned = s.connect([&] { ++calls; });
  s.emit();
  CHECK(calls == 0);
  CHECK(s.size() == 1);
}
