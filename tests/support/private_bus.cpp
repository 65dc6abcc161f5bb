#include "tests/support/private_bus.hpp"

#include <signal.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#ifndef PITWALL_SOURCE_DIR
#error "PITWALL_SOURCE_DIR must name the source tree (it holds tests/support/bus.conf)"
#endif

namespace pitwall::testing {

namespace {
std::string readLine(FILE* f) {
  char buf[512];
  if (!std::fgets(buf, sizeof buf, f)) return {};
  std::string s(buf);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}
}  // namespace

PrivateBus::PrivateBus() {
  std::string cmd = "dbus-daemon --config-file=" PITWALL_SOURCE_DIR
                    "/tests/support/bus.conf --fork --nosyslog --print-address=1 --print-pid=1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot start dbus-daemon");
  address_ = readLine(p);
  std::string pid = readLine(p);
  int status = ::pclose(p);
  if (address_.empty() || pid.empty() || status != 0)
    throw std::runtime_error("dbus-daemon did not start (is the dbus-daemon package installed?)");
  pid_ = static_cast<pid_t>(std::stol(pid));
  if (const char* v = std::getenv("DBUS_SYSTEM_BUS_ADDRESS")) hadSystem_ = true, oldSystem_ = v;
  if (const char* v = std::getenv("DBUS_SESSION_BUS_ADDRESS")) hadSession_ = true, oldSession_ = v;
  ::setenv("DBUS_SYSTEM_BUS_ADDRESS", address_.c_str(), 1);
  ::setenv("DBUS_SESSION_BUS_ADDRESS", address_.c_str(), 1);
}

PrivateBus::~PrivateBus() {
  if (pid_ > 0) ::kill(pid_, SIGTERM);  // forked twice: not our child, nothing to reap
  if (hadSystem_)
    ::setenv("DBUS_SYSTEM_BUS_ADDRESS", oldSystem_.c_str(), 1);
  else
    ::unsetenv("DBUS_SYSTEM_BUS_ADDRESS");
  if (hadSession_)
    ::setenv("DBUS_SESSION_BUS_ADDRESS", oldSession_.c_str(), 1);
  else
    ::unsetenv("DBUS_SESSION_BUS_ADDRESS");
}

}  // namespace pitwall::testing
