#include "engine/drive/keyboard.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "engine/core/log.hpp"
#include "engine/drive/key_parser.hpp"

namespace pitwall::drive {

using boost::asio::posix::stream_descriptor;

namespace {
constexpr const char* kLog = "keyboard";
constexpr const char* kHolder = "keyboard";
constexpr int kSteps = 10;  // ↑ and ↓ move the throttle by a tenth

// The terminal's modes as they were before cbreak, for the exit paths that run no destructor
// (exit() from anywhere): one keyboard at a time, restored by an atexit handler too.
struct SavedTerminal {
  bool active = false;
  int fd = -1;
  termios modes{};
};
SavedTerminal saved;

void restoreSaved() {
  if (!saved.active) return;
  ::tcsetattr(saved.fd, TCSANOW, &saved.modes);
  saved.active = false;
}
}  // namespace

struct Keyboard::Impl {
  Impl(Loop& loop, Seats& seats, int fd) : loop(loop), seats(seats), fd(fd), input(loop.io()) {}

  ~Impl() {
    *alive = false;
    boost::system::error_code ec;
    input.close(ec);  // our dup of the terminal; the terminal itself stays open
    if (seated) seats.release(kHolder, "the keyboard stops");
    restoreSaved();
  }

  Result<bool, std::string> start();
  void wait();
  void read();
  void waited(const boost::system::error_code& ec);
  void key(Key k);
  void lost(const std::string& what, const std::string& why);  // logged; the seat's reason
  bool ready();

  Loop& loop;
  Seats& seats;
  int fd;
  stream_descriptor input;
  KeyParser parser;
  int tenths = 0;  // the throttle asked, in tenths
  bool seated = false;
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
};

Result<bool, std::string> Keyboard::Impl::start() {
  if (!::isatty(fd))
    return Unexpected(
        "--keyboard needs a terminal: the standard input is " +
        std::string(errno == ENOTTY ? "not one (a pipe or a file)" : std::strerror(errno)) +
        "; run pitwall in a terminal, or drive with --gamepads or a phone");
  if (saved.active)
    return Unexpected(
        std::string("--keyboard: another keyboard already drives from this terminal"));
  termios modes{};
  if (::tcgetattr(fd, &modes) < 0)
    return Unexpected("--keyboard needs a terminal: cannot read its modes: " +
                      std::string(std::strerror(errno)));
  auto got = seats.claim(kHolder, Holder::Keyboard, 0, "keyboard");
  if (!got) return Unexpected("--keyboard: " + got.error());
  seated = true;
  // cbreak: keys one at a time (no ICANON), not echoed (no ECHO); ISIG stays, so Ctrl-C is still
  // SIGINT and stops the run (and the cars) as always. But not Ctrl-Z: SIGTSTP would freeze the
  // whole loop with the cars at speed and nothing left to stop them (VSUSP off; POSIX
  // _POSIX_VDISABLE), until the modes are put back; nor Ctrl-\: SIGQUIT's default action ends
  // the process at once, dumping core, with no stop for any car (VQUIT off).
  termios cbreak = modes;
  cbreak.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
  cbreak.c_lflag |= ISIG;
  cbreak.c_cc[VMIN] = 1;
  cbreak.c_cc[VTIME] = 0;
  cbreak.c_cc[VSUSP] = _POSIX_VDISABLE;
  cbreak.c_cc[VQUIT] = _POSIX_VDISABLE;
  saved = SavedTerminal{true, fd, modes};
  static bool registered = false;
  if (!registered) registered = std::atexit(restoreSaved) == 0;
  if (::tcsetattr(fd, TCSANOW, &cbreak) < 0) {
    const int e = errno;
    saved.active = false;
    return Unexpected("--keyboard needs a terminal: cannot set its modes: " +
                      std::string(std::strerror(e)));
  }
  // A dup for Asio, which closes what it owns: the terminal stays open for the rest of the
  // program. It is never made non-blocking (that flag is shared with the shell's terminal): it
  // is only read when poll says a byte is there.
  int copy = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);
  if (copy < 0) {
    const int e = errno;
    restoreSaved();
    return Unexpected("--keyboard: cannot read the terminal: " + std::string(std::strerror(e)));
  }
  input.assign(copy);
  log::info(kLog, "driving car " + std::to_string(got.value()) +
                      ": ↑/↓ throttle, ←/→ lanes, space stops, Ctrl-C ends the run");
  wait();
  return true;
}

void Keyboard::Impl::wait() {
  std::weak_ptr<bool> weak = alive;
  input.async_wait(stream_descriptor::wait_read, [this, weak](const boost::system::error_code& ec) {
    if (!weak.expired()) waited(ec);
  });
}

void Keyboard::Impl::waited(const boost::system::error_code& ec) {
  if (ec == boost::asio::error::operation_aborted) return;
  if (ec) {  // the terminal cannot be waited for: as good as hung up
    lost("cannot wait for the terminal: " + ec.message(), "the terminal cannot be read");
    return;
  }
  std::weak_ptr<bool> weak = alive;
  read();
  if (!weak.expired() && seated) wait();
}

bool Keyboard::Impl::ready() {
  pollfd p{input.native_handle(), POLLIN, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLHUP | POLLERR)) != 0;
}

void Keyboard::Impl::read() {
  // Asio waits edge-triggered: everything there now is read (a key held down repeats).
  std::weak_ptr<bool> weak = alive;
  while (ready()) {
    char buf[256];
    ssize_t n = ::read(input.native_handle(), buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) return;
    if (n <= 0) {  // the terminal hung up
      lost(n == 0 ? std::string("the terminal closed")
                  : "cannot read the terminal: " + std::string(std::strerror(errno)),
           "the terminal closed");
      return;
    }
    for (Key k : parser.feed(std::string_view(buf, static_cast<std::size_t>(n)))) {
      key(k);
      if (weak.expired() || !seated) return;
    }
  }
}

// The terminal cannot be read any more: the keyboard lets go of its seat, so its car slows to a
// stop instead of keeping the last throttle asked for. No more waits.
void Keyboard::Impl::lost(const std::string& what, const std::string& why) {
  log::warn(kLog, what);
  if (seated) seats.release(kHolder, why);
  seated = false;
}

void Keyboard::Impl::key(Key k) {
  int lane = 0;
  switch (k) {
    case Key::Up:
      tenths = std::min(tenths + 1, kSteps);
      break;
    case Key::Down:
      tenths = std::max(tenths - 1, 0);
      break;
    case Key::Space:
      tenths = 0;
      break;
    case Key::Left:
      lane = -1;
      break;
    case Key::Right:
      lane = +1;
      break;
  }
  auto sent = seats.input(kHolder, tenths / static_cast<double>(kSteps), lane);
  if (!sent) {
    log::warn(kLog, sent.error());
    return;
  }
  log::info(kLog, "throttle " + std::to_string(tenths * 10) + " %" +
                      (lane < 0   ? ", a lane left"
                       : lane > 0 ? ", a lane right"
                                  : ""));
}

Keyboard::Keyboard(Loop& loop, Seats& seats, int fd)
    : impl_(std::make_unique<Impl>(loop, seats, fd)) {}

Keyboard::~Keyboard() = default;

Result<bool, std::string> Keyboard::start() {
  return impl_->start();
}

void Keyboard::waited(const boost::system::error_code& ec) {
  impl_->waited(ec);
}

}  // namespace pitwall::drive
