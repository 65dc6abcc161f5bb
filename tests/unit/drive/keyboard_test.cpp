// The terminal's keyboard as a controller (engine/drive/keyboard.hpp), on a real pseudo-terminal:
// cbreak while it drives, the keys into the seat, the terminal's modes back when it is gone.
#include "engine/drive/keyboard.hpp"

#include <doctest/doctest.h>
#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <boost/asio/error.hpp>
#include <string>

#include "engine/drive/seats.hpp"
#include "engine/fleet/fleet.hpp"

using namespace pitwall;

namespace {

struct Pty {
  int master = -1, slave = -1;
  Pty() {
    REQUIRE(::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0);
    ::fcntl(master, F_SETFL, O_NONBLOCK);
  }
  ~Pty() {
    ::close(master);
    ::close(slave);
  }
  void type(const std::string& bytes) const {
    REQUIRE(::write(master, bytes.data(), bytes.size()) == static_cast<ssize_t>(bytes.size()));
  }
  tcflag_t lflag() const { return modes().c_lflag; }
  termios modes() const {
    termios t{};
    REQUIRE(::tcgetattr(slave, &t) == 0);
    return t;
  }
};

struct Rig {
  Loop loop{ClockKind::Real};
  Fleet fleet{loop};
  drive::Seats seats{loop, fleet, 2};
  void run(double seconds) {
    loop.after(fromSeconds(seconds), [this] { loop.stop(); });
    loop.run();
  }
};

// A keyboard started on a pty: it holds seat 1.
struct Driving {
  Rig r;
  Pty pty;
  drive::Keyboard k{r.loop, r.seats, pty.slave};
  Driving() { REQUIRE(k.start()); }
  // Types `bytes` and lets the loop read them; seat 1's throttle then.
  double type(const std::string& bytes) {
    pty.type(bytes);
    r.run(0.05);
    return r.seats.seat(1)->throttle;
  }
};

}  // namespace

TEST_CASE("keyboard: not a terminal, start() says --keyboard needs one and takes no seat") {
  Rig r;
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  drive::Keyboard k(r.loop, r.seats, fds[0]);
  auto started = k.start();
  REQUIRE_FALSE(started);
  CHECK(started.error().find("--keyboard needs a terminal: ") == 0);
  CHECK_FALSE(r.seats.seat(1)->held());
  ::close(fds[0]);
  ::close(fds[1]);
}

TEST_CASE("keyboard: cbreak while it drives (no ICANON, no ECHO, ISIG kept), restored after") {
  Rig r;
  Pty pty;
  const tcflag_t before = pty.lflag();
  REQUIRE((before & ICANON));
  REQUIRE((before & ECHO));
  {
    drive::Keyboard k(r.loop, r.seats, pty.slave);
    REQUIRE(k.start());
    const tcflag_t during = pty.lflag();
    CHECK_FALSE((during & ICANON));
    CHECK_FALSE((during & ECHO));
    CHECK((during & ISIG));
    CHECK(r.seats.seat(1)->held());
    CHECK(r.seats.seat(1)->kind == drive::Holder::Keyboard);
  }
  CHECK(pty.lflag() == before);
  CHECK_FALSE(r.seats.seat(1)->held());  // let go with the keyboard
}

TEST_CASE("keyboard: ↑ adds a tenth of throttle, ↓ takes one, space stops, ←/→ step lanes") {
  Driving d;
  // the third arrow split across two writes
  CHECK(d.type("\x1b[A\x1b[A\x1b") == doctest::Approx(0.2));
  CHECK(d.type("[A\x1bOA") == doctest::Approx(0.4));
  CHECK(d.type("\x1b[B") == doctest::Approx(0.3));
  d.type("\x1b[D\x1b[D\x1b[C");
  CHECK(d.r.seats.takeLanes(1) == -1);
  CHECK(d.type(" ") == 0.0);
  // the throttle stays within 0..1 however often a key is pressed
  std::string ups;
  for (int i = 0; i < 15; ++i) ups += "\x1b[A";
  CHECK(d.type(ups) == 1.0);
  std::string downs;
  for (int i = 0; i < 15; ++i) downs += "\x1b[B";
  CHECK(d.type(downs) == 0.0);
  CHECK(d.r.seats.seat(1)->live);  // a keyboard is never silent: its throttle holds
}

TEST_CASE("keyboard: no free seat, start() says so and leaves the terminal as it was") {
  Rig r;
  Pty pty;
  REQUIRE(r.seats.claim("a", drive::Holder::Phone, 1));
  REQUIRE(r.seats.claim("b", drive::Holder::Phone, 2));
  const tcflag_t before = pty.lflag();
  drive::Keyboard k(r.loop, r.seats, pty.slave);
  auto started = k.start();
  REQUIRE_FALSE(started);
  CHECK(started.error().find("every seat is taken") != std::string::npos);
  CHECK(pty.lflag() == before);
}

TEST_CASE("keyboard: the terminal hung up, the seat is let go (the car slows to a stop)") {
  Driving d;
  CHECK(d.type("\x1b[A") == doctest::Approx(0.1));
  ::close(d.pty.master);
  d.pty.master = ::open("/dev/null", O_RDONLY);  // for the destructor's close
  d.r.run(0.05);
  CHECK_FALSE(d.r.seats.seat(1)->held());
}

TEST_CASE(
    "keyboard: Ctrl-Z and Ctrl-backslash are off while it drives (no SIGTSTP, no SIGQUIT), back "
    "after") {
  Rig r;
  Pty pty;
  const cc_t before = pty.modes().c_cc[VSUSP];
  const cc_t quit = pty.modes().c_cc[VQUIT];
  REQUIRE(before != _POSIX_VDISABLE);  // a fresh pty: ^Z
  REQUIRE(quit != _POSIX_VDISABLE);    // and ^\ (backslash)
  {
    drive::Keyboard k(r.loop, r.seats, pty.slave);
    REQUIRE(k.start());
    CHECK(pty.modes().c_cc[VSUSP] == _POSIX_VDISABLE);
    CHECK(pty.modes().c_cc[VQUIT] == _POSIX_VDISABLE);
    CHECK(pty.modes().c_cc[VINTR] != _POSIX_VDISABLE);  // Ctrl-C still ends the run
  }
  CHECK(pty.modes().c_cc[VSUSP] == before);
  CHECK(pty.modes().c_cc[VQUIT] == quit);
}

TEST_CASE("keyboard: a wait for the terminal that fails lets go of the seat; a cancel does not") {
  Driving d;
  CHECK(d.type("\x1b[A\x1b[A") == doctest::Approx(0.2));
  d.k.waited(boost::asio::error::operation_aborted);
  CHECK(d.r.seats.seat(1)->held());
  d.k.waited(boost::asio::error::bad_descriptor);
  CHECK_FALSE(d.r.seats.seat(1)->held());  // the car slows to a stop, not on at 0.2
}
