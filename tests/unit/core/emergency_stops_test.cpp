#include "engine/core/emergency_stops.hpp"

#include <doctest/doctest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <vector>

using namespace pitwall;
using namespace std::chrono_literals;

namespace {
// A connected pair of sequenced-packet sockets, as BlueZ's AcquireWrite gives one end of.
struct Pair {
  int ours = -1, car = -1;
  Pair() {
    int fds[2];
    REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) == 0);
    ours = fds[0];
    car = fds[1];
  }
  ~Pair() {
    ::close(ours);
    ::close(car);
  }
  // What the car got next, waiting at most `ms` (empty when nothing came).
  std::vector<std::uint8_t> received(int ms) const {
    struct pollfd p {
      car, POLLIN, 0
    };
    if (::poll(&p, 1, ms) != 1) return {};
    std::array<std::uint8_t, 64> buffer{};
    ssize_t n = ::recv(car, buffer.data(), buffer.size(), 0);
    if (n <= 0) return {};
    return {buffer.begin(), buffer.begin() + n};
  }
};
const std::vector<std::uint8_t> kStop{0x06, 0x24, 0x00, 0x00, 0xd4, 0x30, 0x00};

// One car registered, and a real loop watched with a limit of 300 ms.
struct Watched {
  Pair car;
  int slot = emergency::add(car.ours, kStop);
  Loop loop{ClockKind::Real};
  Watchdog watchdog{loop, std::chrono::milliseconds(300)};
  Watched() { REQUIRE(slot >= 0); }
  ~Watched() { emergency::remove(slot); }
};
}  // namespace

TEST_CASE("emergency stops: every registered socket gets its frame, a removed one nothing") {
  Pair a, b;
  int slotA = emergency::add(a.ours, kStop);
  int slotB = emergency::add(b.ours, std::vector<std::uint8_t>{0x01, 0x16});
  REQUIRE(slotA >= 0);
  REQUIRE(slotB >= 0);
  CHECK(emergency::count() == 2);
  CHECK(emergency::sendAll() == 2);
  CHECK(a.received(1000) == kStop);
  CHECK(b.received(1000) == std::vector<std::uint8_t>{0x01, 0x16});
  emergency::remove(slotB);
  CHECK(emergency::sendAll() == 1);
  CHECK(a.received(1000) == kStop);
  CHECK(b.received(0).empty());
  emergency::remove(slotA);
  CHECK(emergency::count() == 0);
  CHECK(emergency::sendAll() == 0);
  // nothing registered for a closed socket, an empty or oversized frame
  CHECK(emergency::add(-1, kStop) == -1);
  CHECK(emergency::add(a.ours, std::vector<std::uint8_t>{}) == -1);
  CHECK(emergency::add(a.ours, std::vector<std::uint8_t>(emergency::kFrameMax + 1, 0)) == -1);
}

// The adversary: a callback that never gives the loop back (it waits, inside the loop, for the
// very frame only the watchdog can send). The watchdog's thread sees the loop silent past its
// limit and sends the stop; the callback gets it, returns, and the loop turns again.
TEST_CASE("the watchdog stops the cars when the loop does not turn, once, and rearms") {
  Watched w;
  Pair& car = w.car;
  Loop& loop = w.loop;
  Watchdog& watchdog = w.watchdog;
  std::vector<std::uint8_t> got, later;
  loop.after(10ms, [&] {
    got = car.received(20000);  // the loop is wedged here until the stop comes
    later = car.received(500);  // still wedged: no second stop for the same stall
  });
  loop.after(50ms, [&] { loop.stop(); });
  loop.run();
  CHECK(got == kStop);
  CHECK(later.empty());
  CHECK(watchdog.fired() == 1);
}

TEST_CASE("the watchdog does not fire on a loop that turns, nor while held") {
  Watched w;
  Pair& car = w.car;
  Loop& loop = w.loop;
  Watchdog& watchdog = w.watchdog;
  // a second of a loop that turns, then a held stall (a suspended run)
  loop.after(1s, [&] {
    watchdog.hold(true);
    CHECK(car.received(600).empty());
    watchdog.hold(false);
    loop.stop();
  });
  loop.run();
  CHECK(watchdog.fired() == 0);
}
