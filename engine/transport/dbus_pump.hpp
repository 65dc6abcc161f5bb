#pragma once
// Drives one sdbus-c++ connection from the engine's loop: no hidden sdbus threads.
//
// sdbus-c++ 1.2.0 exposes {fd, events, absolute timeout} through getEventLoopPollData(). The pump
// waits for the fd (read, and write when sd-bus has output queued) and for the timeout on the
// loop's io_context; on every wake it drains processPendingRequest() and re-arms from fresh poll
// data. 1.2.0 has no event fd to wake a poller, so code that makes sdbus calls outside an sdbus
// callback calls kick() afterwards (the calls made inside callbacks are covered by the re-arm).
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/steady_timer.hpp>
#include <memory>

#include "engine/core/loop.hpp"

namespace sdbus {
class IConnection;
}

namespace pitwall {

class DbusPump {
 public:
  // The connection must outlive the pump. The loop must run on a real clock.
  DbusPump(Loop& loop, sdbus::IConnection& connection);
  ~DbusPump();
  DbusPump(const DbusPump&) = delete;
  DbusPump& operator=(const DbusPump&) = delete;

  // Processes what is pending and re-arms, soon, on the loop. Cheap; calls coalesce.
  void kick();
  sdbus::IConnection& connection() { return connection_; }
  Loop& loop() { return loop_; }
  // Drains and re-arms now (tests and shutdown paths that must flush before returning).
  void process();

 private:
  void rearm();
  void wait(boost::asio::posix::stream_descriptor::wait_type type, bool& waiting);

  Loop& loop_;
  sdbus::IConnection& connection_;
  boost::asio::posix::stream_descriptor fd_;
  boost::asio::steady_timer timer_;
  bool readWaiting_ = false, writeWaiting_ = false, kicked_ = false;
  std::uint64_t armedTimeout_ = 0;
  std::shared_ptr<bool> alive_;
};

}  // namespace pitwall
