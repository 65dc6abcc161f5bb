#include "engine/core/inotify.hpp"

#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "engine/core/log.hpp"

namespace pitwall {

Result<std::unique_ptr<Inotify>, std::string> Inotify::open(Loop& loop) {
  int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (fd < 0) return Unexpected(std::string(std::strerror(errno)));
  std::unique_ptr<Inotify> made(new Inotify(loop, fd));
  made->wait();
  return made;
}

Inotify::Inotify(Loop& loop, int fd) : fd_(loop.io(), fd) {}

Inotify::~Inotify() {
  *alive_ = false;
  boost::system::error_code ec;
  fd_.close(ec);
}

Result<int, std::string> Inotify::add(const std::string& folder, std::uint32_t mask) {
  int wd = ::inotify_add_watch(fd_.native_handle(), folder.c_str(), mask);
  if (wd < 0) return Unexpected(std::string(std::strerror(errno)));
  return wd;
}

void Inotify::wait() {
  std::weak_ptr<bool> alive = alive_;
  fd_.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                 [this, alive](const boost::system::error_code& ec) {
                   if (alive.expired() || ec) return;
                   const bool readable = read();
                   if (readable && !alive.expired()) wait();
                 });
}

bool Inotify::read() {
  alignas(inotify_event) char buf[4096];
  std::weak_ptr<bool> alive = alive_;
  for (;;) {
    ssize_t n = ::read(fd_.native_handle(), buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
      log::warn("inotify", std::string("reading the file watch failed: ") + std::strerror(errno) +
                               "; no more changes are seen");
      return false;
    }
    if (n <= 0) return true;  // EAGAIN: all read
    for (char* p = buf; p < buf + n;) {
      auto* e = reinterpret_cast<inotify_event*>(p);
      p += sizeof(inotify_event) + e->len;
      // Called through a copy: a callback that destroys this watch destroys the members too.
      if (e->mask & IN_Q_OVERFLOW) {
        if (Overflow call = onOverflow) call();
      } else if (Event call = onEvent) {
        // The name is padded with NULs to its length; none when the event is the folder's own.
        call(e->wd, e->mask, e->len ? std::string(e->name) : std::string());
      }
      if (alive.expired()) return false;  // a callback destroyed this watch: buf is ours only
    }
  }
}

}  // namespace pitwall
