// Messages as JSON objects for `pitwall decode` and `--record` files. The fields and their names
// come from message_fields.hpp, the list the codec reads and writes by: the struct field names
// (they carry the unit); optional fields are left out when absent.
#include "engine/protocol/anki/message_json.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <string>
#include <type_traits>

#include "engine/core/hex.hpp"
#include "engine/protocol/anki/message_fields.hpp"

namespace pitwall::anki {
namespace {

using nlohmann::json;

// ---- one field's value ----

// Integers and bools as they are.
template <class V>
json value(const V& v) {
  return v;
}

// A float as the shortest decimal that reads back to it (20.0f → 20, 0.1f → 0.1, not
// 0.10000000149011612). JSON has no NaN or infinity: those become null (nlohmann's choice).
json value(float v) {
  if (!std::isfinite(v)) return nullptr;
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  double d = v;
  std::from_chars(buf, end, d);
  return d;
}

// Enum fields as words; a value outside the enum (a decoded frame may hold one) stays a number.
json value(TurnType t) {
  switch (t) {
    case TurnType::None:
      return "none";
    case TurnType::Left:
      return "left";
    case TurnType::Right:
      return "right";
    case TurnType::UTurn:
      return "uturn";
    case TurnType::UTurnJump:
      return "uturn-jump";
  }
  return static_cast<int>(t);
}

json value(TurnTrigger t) {
  switch (t) {
    case TurnTrigger::Immediate:
      return "immediate";
    case TurnTrigger::Intersection:
      return "intersection";
  }
  return static_cast<int>(t);
}

// A struct with a field list (a lights pattern's channel): an object, as a message's fields are.
template <fields::Described T>
json value(const T& record);

// A field as its message shows it: most fields stand alone, but a lights pattern lists only the
// channels in use (channel_count, at most the 3 slots the frame has).
template <class M, class V>
json value(const M&, const V& v) {
  return value(v);
}

json value(const LightsPattern& m, const std::array<LightChannel, 3>& channels) {
  json in_use = json::array();
  for (std::size_t i = 0; i < m.channel_count && i < channels.size(); ++i) {
    in_use.push_back(value(channels[i]));
  }
  return in_use;
}

// ---- a message's fields ----

// Every field under its name (message_fields.hpp), optional fields only when present.
template <class T>
void addFields(json& j, const T& m) {
  fields::forEach<T>([&](const auto& field) {
    const auto& v = m.*field.member;
    if constexpr (fields::IsOptional<std::remove_cvref_t<decltype(v)>>::value) {
      if (v) j[field.name] = value(*v);
    } else {
      j[field.name] = value(m, v);
    }
  });
}

template <fields::Described T>
json value(const T& record) {
  json j = json::object();
  addFields(j, record);
  return j;
}

// The whole frame as space-separated hex bytes: "03 99 01 02".
void addFields(json& j, const Unknown& m) {
  j["raw"] = toHex(m.raw.span());
}

}  // namespace

json toJson(const Message& message) {
  json j = json::object();
  j["name"] = name(message);
  j["id"] = hexByte(messageId(message));
  std::visit([&](const auto& m) { addFields(j, m); }, message);
  return j;
}

}  // namespace pitwall::anki
