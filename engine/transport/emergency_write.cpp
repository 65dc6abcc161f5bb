#include "engine/transport/emergency_write.hpp"

#include <sdbus-c++/sdbus-c++.h>
#include <chrono>
#include <map>

#include "engine/transport/bluez.hpp"

namespace pitwall::ble {

emergency::Stopper writeValueStopper(std::string path, std::vector<std::uint8_t> value,
                                     bool withResponse) {
  return [path = std::move(path), value = std::move(value), withResponse] {
    try {
      auto connection = sdbus::createSystemBusConnection();
      auto proxy = sdbus::createProxy(*connection, kService, path);
      std::map<std::string, sdbus::Variant> options;
      options["type"] = sdbus::Variant(std::string(withResponse ? "request" : "command"));
      proxy->callMethod("WriteValue")
          .onInterface(kCharIface)
          .withTimeout(std::chrono::milliseconds(500))
          .withArguments(value, options);
      return true;
    } catch (const sdbus::Error&) {
      return false;  // no bus, no such characteristic, no answer in time: nothing more to do
    }
  };
}

}  // namespace pitwall::ble
