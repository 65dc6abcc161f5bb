#pragma once
// The LE connection interval BlueZ asks each car for (docs/bluetooth.md "Connection interval and
// latency"). BlueZ has no D-Bus interface for a connection's interval (bluez/bluez#731): every LE
// connection asks for main.conf's [LE] MinConnectionInterval..MaxConnectionInterval (units of
// 1.25 ms), else the kernel's default 24..40 (30–50 ms), and what the controller grants is not
// told. pitwall says what is asked, and whether it suits the cars an adapter holds.
#include <string>

namespace pitwall::ble {

struct LeInterval {
  double minMs = 30;
  double maxMs = 50;
  bool fromConfig = false;  // main.conf set it; else the kernel's default
};

// Reads [LE] MinConnectionInterval and MaxConnectionInterval of BlueZ's main.conf at `path`; a
// file that is not there, cannot be read, or leaves them out gives the kernel's default.
LeInterval leInterval(const std::string& path = "/etc/bluetooth/main.conf");

// How many cars one controller serves at that interval: each gets a connection event of up to
// kEventMs (a notification and a command each way), and the events of all must fit in the
// longest interval BlueZ asks for.
inline constexpr double kEventMs = 3.75;
int carsSuited(const LeInterval& interval);

// The sentence for an adapter holding `cars` cars: what BlueZ asks each for, and — when the
// interval is too short for that many — what to do. `suits` is set to whether it does.
std::string intervalSentence(const std::string& adapter, int cars, const LeInterval& interval,
                             bool& suits);

}  // namespace pitwall::ble
