#pragma once
// Alphabot messages as JSON objects for `pitwall decode alphabot`: "name", "packet" (the WLAN
// packet id in hex, absent for the BLE-only answers; not "id", which is the obstacle's or the
// anchor's id in the reference tables) and the fields named as in alphabot.md's tables
// (degree, distance, x, y, id, width, height, speed, steer, time, waypoints). The toggle field
// is {"settings": n, "logging": n, "on": [names of the bits set]} (toggles.hpp names them).
#include <nlohmann/json.hpp>

#include "engine/protocol/alphabot/messages.hpp"

namespace pitwall::alphabot {

nlohmann::json toJson(const Request& request);
nlohmann::json toJson(const Response& response);
nlohmann::json toJson(const Toggles& toggles);

}  // namespace pitwall::alphabot
