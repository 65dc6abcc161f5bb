#include "engine/transport/dbus_pump.hpp"

#include <poll.h>

#include <sdbus-c++/Error.h>
#include <sdbus-c++/IConnection.h>

#include "engine/core/log.hpp"

namespace pitwall {

DbusPump::DbusPump(Loop& loop, sdbus::IConnection& connection)
    : loop_(loop),
      connection_(connection),
      fd_(loop.io()),
      timer_(loop.io()),
      alive_(std::make_shared<bool>(true)) {
  fd_.assign(connection_.getEventLoopPollData().fd);
  rearm();
}

DbusPump::~DbusPump() {
  *alive_ = false;
  boost::system::error_code ec;
  fd_.cancel(ec);
  timer_.cancel();
  fd_.release();  // sd-bus owns the descriptor
}

void DbusPump::kick() {
  if (kicked_) return;
  kicked_ = true;
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive] {
    if (alive.expired()) return;
    kicked_ = false;
    process();
  });
}

void DbusPump::process() {
  try {
    while (connection_.processPendingRequest()) {
    }
  } catch (const std::exception& e) {
    // A handler let an exception escape; sd-bus is left consistent, the message is lost.
    log::error("dbus", std::string("a D-Bus handler failed: ") + e.what());
  }
  rearm();
}

void DbusPump::wait(boost::asio::posix::stream_descriptor::wait_type type, bool& waiting) {
  if (waiting) return;
  waiting = true;
  std::weak_ptr<bool> alive = alive_;
  fd_.async_wait(type, [this, alive, &waiting](const boost::system::error_code& ec) {
    if (alive.expired()) return;
    waiting = false;
    if (ec == boost::asio::error::operation_aborted) return;
    process();
  });
}

void DbusPump::rearm() {
  auto poll = connection_.getEventLoopPollData();
  std::weak_ptr<bool> alive = alive_;
  if (poll.events & POLLIN) wait(boost::asio::posix::stream_descriptor::wait_read, readWaiting_);
  if (poll.events & POLLOUT) wait(boost::asio::posix::stream_descriptor::wait_write, writeWaiting_);
  if (poll.timeout_usec == armedTimeout_) return;
  armedTimeout_ = poll.timeout_usec;
  if (poll.timeout_usec == UINT64_MAX) {
    timer_.cancel();
    return;
  }
  // sd-bus gives an absolute CLOCK_MONOTONIC time: the clock steady_clock reads on Linux.
  timer_.expires_at(std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::microseconds(poll.timeout_usec))));
  timer_.async_wait([this, alive](const boost::system::error_code& ec) {
    if (alive.expired() || ec == boost::asio::error::operation_aborted) return;
    armedTimeout_ = 0;
    process();
  });
}

}  // namespace pitwall
