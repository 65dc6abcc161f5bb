// The D-Bus pump: sdbus-c++ driven from the engine loop, against a private dbus-daemon.
#include "engine/transport/dbus_pump.hpp"

#include <doctest/doctest.h>

#include <sdbus-c++/sdbus-c++.h>

#include "tests/support/private_bus.hpp"

using namespace pitwall;

TEST_CASE("dbus pump: async calls, replies, signals and timeouts run on the loop") {
  testing::PrivateBus bus;
  Loop loop(ClockKind::Real);
  auto serverConn = sdbus::createSystemBusConnection("org.pitwall.Echo");
  auto clientConn = sdbus::createSystemBusConnection();
  DbusPump serverPump(loop, *serverConn);
  DbusPump clientPump(loop, *clientConn);

  auto object = sdbus::createObject(*serverConn, "/echo");
  int served = 0;
  object->registerMethod("Echo")
      .onInterface("org.pitwall.Echo")
      .implementedAs([&](const std::string& s) {
        ++served;
        return s + "!";
      });
  object->registerMethod("Never")
      .onInterface("org.pitwall.Echo")
      .implementedAs(
          [](sdbus::Result<>&& /*result*/) {});  // never answers: the caller's timeout fires
  object->registerSignal("Tick").onInterface("org.pitwall.Echo").withParameters<int>();
  object->finishRegistration();

  auto proxy = sdbus::createProxy(*clientConn, "org.pitwall.Echo", "/echo");
  std::vector<int> ticks;
  proxy->uponSignal("Tick").onInterface("org.pitwall.Echo").call([&](int n) {
    ticks.push_back(n);
  });
  proxy->finishRegistration();
  // Setup made synchronous calls outside the pumps (AddMatch, RequestName): re-arm both.
  serverPump.kick();
  clientPump.kick();

  SUBCASE("ten thousand round trips, each answered on the loop") {
    int replies = 0;
    std::function<void()> next = [&] {
      proxy->callMethodAsync("Echo")
          .onInterface("org.pitwall.Echo")
          .withArguments(std::string("lap"))
          .uponReplyInvoke([&](const sdbus::Error* e, const std::string& r) {
            if (e) FAIL(e->getName() << ": " << e->getMessage());
            CHECK(r == "lap!");
            if (++replies == 10000)
              loop.stop();
            else
              next();
          });
    };
    next();
    clientPump.kick();
    loop.after(std::chrono::seconds(30), [&] { loop.stop(); });
    loop.run();
    CHECK(replies == 10000);
    CHECK(served == 10000);
  }

  SUBCASE("signals arrive in order") {
    for (int i = 0; i < 5; ++i)
      object->emitSignal("Tick").onInterface("org.pitwall.Echo").withArguments(i);
    serverPump.kick();
    std::function<void()> poll = [&] {
      if (ticks.size() == 5) return loop.stop();
      loop.after(std::chrono::milliseconds(1), poll);
    };
    poll();
    loop.after(std::chrono::seconds(10), [&] { loop.stop(); });
    loop.run();
    CHECK(ticks == std::vector<int>{0, 1, 2, 3, 4});
  }

  SUBCASE("a method call timeout fires through the timer path") {
    std::string error;
    proxy->callMethodAsync("Never")
        .onInterface("org.pitwall.Echo")
        .withTimeout(std::chrono::milliseconds(200))
        .uponReplyInvoke([&](const sdbus::Error* e) {
          error = e ? e->getName() : "none";
          loop.stop();
        });
    clientPump.kick();
    loop.after(std::chrono::seconds(10), [&] { loop.stop(); });
    auto t0 = loop.now();
    loop.run();
    CHECK(error == "org.freedesktop.DBus.Error.NoReply");  // sd-bus names a timeout so
    CHECK(loop.now() - t0 >= std::chrono::milliseconds(190));
  }
}
