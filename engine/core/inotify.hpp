#pragma once
// One inotify instance on the engine loop: folders added with a mask, and a callback per event as
// the kernel queues them. Shared by the script watch for hot reload (engine/core/file_watch.hpp)
// and the gamepads' hot-plug (engine/drive/gamepads.hpp).
//
// Each time the fd is readable the queue is read until it is empty (EAGAIN), and every event is
// handed to onEvent in order; IN_Q_OVERFLOW (the kernel's queue was full: events were lost) goes
// to onOverflow instead. Either callback may destroy this Inotify, and its owner with it: the
// read stops at once and nothing of the destroyed object is touched afterwards (an alive flag the
// wait and the read hold weakly; the destructor closes the fd, which cancels the wait).
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"

namespace pitwall {

class Inotify {
 public:
  // `name` is the file's name in the watched folder; empty for an event on the folder itself
  // (IN_IGNORED: the folder is gone, IN_DELETE_SELF, …).
  using Event = std::function<void(int wd, std::uint32_t mask, const std::string& name)>;
  using Overflow = std::function<void()>;

  // A new instance, waiting on the loop; the error is the reason (too many instances, …).
  static Result<std::unique_ptr<Inotify>, std::string> open(Loop& loop);
  ~Inotify();
  Inotify(const Inotify&) = delete;
  Inotify& operator=(const Inotify&) = delete;

  // Watches `folder` for the events in `mask` (IN_CREATE | …): the watch descriptor that events
  // carry (the same one again for a folder added twice), or the reason it cannot be watched,
  // strerror's sentence ("No such file or directory", "Permission denied").
  Result<int, std::string> add(const std::string& folder, std::uint32_t mask);

  Event onEvent;
  Overflow onOverflow;

 private:
  Inotify(Loop& loop, int fd);
  void wait();
  // Reads until the queue is empty; false when reading failed for good (said in the log): the
  // watch then stops rather than spin on an fd that stays readable.
  bool read();

  boost::asio::posix::stream_descriptor fd_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace pitwall
