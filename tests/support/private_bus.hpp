#pragma once
// A private dbus-daemon for one test: started on a socket in /tmp with tests/support/bus.conf,
// exported as DBUS_SYSTEM_BUS_ADDRESS (and the session address) so that production code that
// opens "the system bus" talks to it, and killed when the object goes away.
#include <sys/types.h>
#include <string>

namespace pitwall::testing {

class PrivateBus {
 public:
  PrivateBus();  // throws std::runtime_error when dbus-daemon cannot start
  ~PrivateBus();
  PrivateBus(const PrivateBus&) = delete;
  PrivateBus& operator=(const PrivateBus&) = delete;

  const std::string& address() const { return address_; }

 private:
  std::string address_;
  pid_t pid_ = -1;
  std::string oldSystem_, oldSession_;
  bool hadSystem_ = false, hadSession_ = false;
};

}  // namespace pitwall::testing
