#include "engine/fleet/connection_interval.hpp"

#include <boost/property_tree/ini_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace pitwall::ble {

namespace {
constexpr double kUnitMs = 1.25;
// The range the Bluetooth Core specification allows: 7.5 ms .. 4 s.
constexpr int kMinUnits = 6, kMaxUnits = 3200;

std::string ms(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", std::round(v * 100) / 100);
  return text;
}
}  // namespace

LeInterval leInterval(const std::string& path) {
  LeInterval out;
  std::ifstream in(path);
  if (!in) return out;
  boost::property_tree::ptree tree;
  try {
    boost::property_tree::read_ini(in, tree);
  } catch (const boost::property_tree::ini_parser_error&) {
    return out;  // bluetoothd would not have read it either
  }
  auto units = [&](const char* key) -> int {
    auto v = tree.get_optional<int>(std::string("LE.") + key);
    return v && *v >= kMinUnits && *v <= kMaxUnits ? *v : 0;
  };
  int lo = units("MinConnectionInterval"), hi = units("MaxConnectionInterval");
  if (lo == 0 && hi == 0) return out;
  if (lo == 0) lo = std::min(hi, 24);
  if (hi == 0) hi = std::max(lo, 40);
  if (lo > hi) return out;  // bluetoothd refuses it, and the kernel's default stands
  out.minMs = lo * kUnitMs;
  out.maxMs = hi * kUnitMs;
  out.fromConfig = true;
  return out;
}

int carsSuited(const LeInterval& interval) {
  return static_cast<int>(std::floor(interval.maxMs / kEventMs + 1e-9));
}

std::string intervalSentence(const std::string& adapter, int cars, const LeInterval& interval,
                             bool& suits) {
  const int suited = carsSuited(interval);
  suits = cars <= suited;
  std::string asked = adapter + ": " + std::to_string(cars) + (cars == 1 ? " car" : " cars") +
                      "; BlueZ asks each for a " +
                      (interval.minMs == interval.maxMs
                           ? ms(interval.maxMs)
                           : ms(interval.minMs) + "–" + ms(interval.maxMs)) +
                      " ms connection interval (" +
                      (interval.fromConfig ? "main.conf's [LE] MinConnectionInterval and "
                                             "MaxConnectionInterval"
                                           : "the kernel's default") +
                      "; what the controller grants is not told)";
  if (suits) return asked + ", which suits up to " + std::to_string(suited) + " cars";
  return asked + ", too short for " + std::to_string(cars) + " cars (each needs about " +
         ms(kEventMs) +
         " ms of it): the controller runs out of airtime and cars drop; raise "
         "MaxConnectionInterval in /etc/bluetooth/main.conf to " +
         std::to_string(static_cast<int>(std::ceil(cars * kEventMs / kUnitMs))) +
         " or more (units of 1.25 ms), or spread the cars over more adapters (--adapter)";
}

}  // namespace pitwall::ble
