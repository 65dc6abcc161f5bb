#pragma once
// The stop of a BLE link that has no write socket of its own (BlueZ refused AcquireWrite, or a
// profile written with WriteValue, as the Alphabot's): a stopper (engine/core/emergency_stops.hpp)
// that writes the stop on the characteristic through a system-bus connection made there and
// then, so that it needs neither the loop nor the link's own connection, which belongs to the
// loop's thread.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/core/emergency_stops.hpp"

namespace pitwall::ble {

// WriteValue(value) on the characteristic at `path` (a command, or a request the device
// acknowledges), given half a second.
emergency::Stopper writeValueStopper(std::string path, std::vector<std::uint8_t> value,
                                     bool withResponse);

}  // namespace pitwall::ble
