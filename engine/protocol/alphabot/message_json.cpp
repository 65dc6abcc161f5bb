#include "engine/protocol/alphabot/message_json.hpp"

#include <cstdio>
#include <string>

#include "engine/core/hex.hpp"
#include "engine/core/overload.hpp"
#include "engine/protocol/alphabot/toggles.hpp"
#include "engine/protocol/alphabot/wlan_codec.hpp"

namespace pitwall::alphabot {
namespace {

using nlohmann::json;

json header(std::string_view name, std::uint8_t id) {
  json j;
  j["name"] = name;
  if (id != 0) j["packet"] = hexByte(id);
  return j;
}

}  // namespace

json toJson(const Toggles& toggles) {
  json on = json::array();
  for (const auto& bit : toggleBits())
    if (isSet(toggles, bit)) on.push_back(bit.name);
  return {{"settings", toggles.settings}, {"logging", toggles.logging}, {"on", on}};
}

json toJson(const Request& request) {
  json j = header(wlan::name(request), wlan::packetId(request));
  std::visit(Overload{[&](const Drive& d) {
                        j["speed"] = d.speed;
                        j["steer"] = d.steer;
                      },
                      [&](const MeasureDistance& m) { j["degree"] = m.degree; },
                      [&](const CalibrateSteering&) {}, [&](const CalibrateCompass&) {},
                      [&](const SetToggles& t) { j["toggles"] = toJson(t.toggles); },
                      [&](const Ping& p) { j["time"] = p.time; },
                      [&](const SetAnchor& a) {
                        j["id"] = a.id;
                        j["x"] = a.x;
                        j["y"] = a.y;
                      },
                      [&](const NavigateTo& n) {
                        j["x"] = n.x;
                        j["y"] = n.y;
                      },
                      [&](const AddObstacle& o) {
                        j["x"] = o.x;
                        j["y"] = o.y;
                        j["width"] = o.width;
                        j["height"] = o.height;
                      },
                      [&](const RemoveObstacleById& r) { j["id"] = r.id; },
                      [&](const RemoveObstacleAt& r) {
                        j["x"] = r.x;
                        j["y"] = r.y;
                      },
                      [&](const ClearObstacles&) {}},
             request);
  return j;
}

json toJson(const Response& response) {
  json j = header(wlan::name(response), wlan::packetId(response));
  std::visit(Overload{[&](const Distance& d) {
                        j["degree"] = d.degree;
                        j["distance"] = d.distance;
                      },
                      [&](const Position& p) {
                        j["x"] = p.x;
                        j["y"] = p.y;
                      },
                      [&](const Path& p) {
                        json w = json::array();
                        for (const auto& wp : p.waypoints) w.push_back({{"x", wp.x}, {"y", wp.y}});
                        j["waypoints"] = w;
                      },
                      [&](const Compass& c) { j["degree"] = c.degree; },
                      [&](const PingReply& p) { j["time"] = p.time; },
                      [&](const ObstacleRegistered& o) {
                        j["id"] = o.id;
                        j["x"] = o.x;
                        j["y"] = o.y;
                        j["width"] = o.width;
                        j["height"] = o.height;
                      },
                      [&](const MapSize& m) {
                        j["length"] = m.length;
                        j["width"] = m.width;
                      },
                      [&](const AnchorPosition& a) {
                        j["id"] = a.id;
                        j["x"] = a.x;
                        j["y"] = a.y;
                      },
                      [&](const CalibrationFinished&) {}},
             response);
  return j;
}

}  // namespace pitwall::alphabot
