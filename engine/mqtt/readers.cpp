// The seed's MQTT topic tree, the reading side: what a remote pitwall reads of the tree — a
// topic's parts and the payloads of S/Information, S/CarStatus, S/HostStatus, S/Cars and E/frame
// — each refused with a sentence when it is not what a bridge publishes.
#include <limits>

#include "engine/core/hex.hpp"
#include "engine/mqtt/payload.hpp"
#include "engine/mqtt/topics.hpp"

namespace pitwall::topics {
using namespace detail;

std::optional<TopicParts> splitTopic(std::string_view topic) {
  auto parts = split(topic);
  if (parts.size() < 4 || parts[0] != "Anki" || parts[2].empty()) return std::nullopt;
  TopicParts out;
  if (parts[1] == "Car")
    out.kind = TopicParts::Kind::Car;
  else if (parts[1] == "Host")
    out.kind = TopicParts::Kind::Host;
  else
    return std::nullopt;
  out.id = std::string(parts[2]);
  out.rest = std::string(topic.substr(parts[0].size() + parts[1].size() + parts[2].size() + 3));
  return out;
}
namespace {

template <typename T>
Result<T, std::string> key(const In& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) return Unexpected{std::string("missing key \"") + name + "\""};
  try {
    return it->get<T>();
  } catch (const Json::exception&) {
    return Unexpected{std::string("\"") + name + "\" has the wrong type (" + excerpt(*it) + ")"};
  }
}

// An unsigned integer no larger than `max` (nlohmann would wrap -1 into a uint32_t).
template <typename T>
Result<T, std::string> unsignedKey(const In& j, const char* name) {
  auto it = j.find(name);
  if (it == j.end()) return Unexpected{std::string("missing key \"") + name + "\""};
  constexpr auto max = std::numeric_limits<T>::max();
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > max)
    return Unexpected{std::string("\"") + name + "\" must be an integer 0.." + std::to_string(max) +
                      ", not " + excerpt(*it)};
  return static_cast<T>(it->get<std::uint64_t>());
}

}  // namespace

Result<CarInfo, std::string> readInformation(std::string_view car, std::string_view payload,
                                             const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  CarInfo info;
  info.id = std::string(car);
  auto address = key<std::string>(*j, "address");
  if (!address) return Unexpected{address.error()};
  info.address = *address;
  // The seed's controller blanks every key when it disconnects the car: an empty address, the
  // rest not read.
  if (info.address.empty()) return info;
  auto identifier = unsignedKey<std::uint32_t>(*j, "identifier");
  if (!identifier) return Unexpected{identifier.error()};
  info.identifier = *identifier;
  auto model = unsignedKey<std::uint8_t>(*j, "modelId");
  if (!model) return Unexpected{model.error()};
  info.model_id = *model;
  // optional: the product id, and pitwall's name
  if (auto product = unsignedKey<std::uint16_t>(*j, "productId")) info.product_id = *product;
  if (auto name = key<std::string>(*j, "name")) info.name = *name;
  // pitwall's bridge says so, with its host; the seed's controller sends neither key
  if (auto bridge = key<std::string>(*j, "bridge"); bridge && *bridge == "pitwall") {
    auto host = key<std::string>(*j, "host");
    if (!host) return Unexpected{host.error() + " (a pitwall bridge names its host)"};
    info.pitwall = true;
    info.host = *host;
  }
  return info;
}

Result<CarOnline, std::string> readCarStatus(std::string_view payload,
                                             const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  CarOnline out;
  auto online = key<bool>(*j, "online");
  if (!online) return Unexpected{online.error()};
  out.online = *online;
  if (auto c = key<bool>(*j, "charging")) out.charging = *c;
  if (auto t = key<bool>(*j, "onTrack")) out.onTrack = *t;
  return out;
}

Result<bool, std::string> readHostStatus(std::string_view payload, const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  return key<bool>(*j, "value");
}

Result<std::vector<std::string>, std::string> readHostCars(std::string_view payload,
                                                           const PayloadLimits& limits) {
  auto j = parse(payload, limits);
  if (!j) return Unexpected{j.error()};
  const In* list = &*j;
  if (j->is_object()) {
    if (j->empty()) return std::vector<std::string>{};  // the seed's controller's "none"
    auto it = j->find("value");                         // earlier pitwall bridges
    if (it == j->end())
      return Unexpected{std::string("must be an array of car ids, not an object")};
    list = &*it;
  }
  if (!list->is_array())
    return Unexpected{"must be an array of car ids, not " + typeName(*list) + " (" +
                      excerpt(*list) + ")"};
  std::vector<std::string> out;
  for (const auto& id : *list) {
    if (!id.is_string())
      return Unexpected{"a car id must be a string, not " + typeName(id) + " (" + excerpt(id) +
                        ")"};
    out.push_back(id.get<std::string>());
  }
  return out;
}

Result<std::vector<std::uint8_t>, std::string> readFrameEvent(std::string_view payload,
                                                              const PayloadLimits& limits) {
  auto j = object(payload, limits);
  if (!j) return Unexpected{j.error()};
  auto text = key<std::string>(*j, "value");
  if (!text) return Unexpected{text.error()};
  auto bytes = fromHex(*text);
  if (!bytes) return Unexpected{quote(bytes.error())};  // a pair may cut a character in two
  return bytes;
}

}  // namespace pitwall::topics
