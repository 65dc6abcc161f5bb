// The JSON both directions of the topic tree share (engine/mqtt/payload.hpp), and quote().
#include "engine/mqtt/payload.hpp"

#include <mosquitto.h>

#include "engine/core/hex.hpp"

namespace pitwall::topics {
namespace detail {

std::string clip(std::string_view s, std::size_t n) {
  if (s.size() <= n) return std::string(s);
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return std::string(s.substr(0, n)) + "…";
}

std::string typeName(const In& v) {
  if (v.is_number_integer()) return "an integer";
  if (v.is_number()) return "a number";
  std::string name = v.type_name();
  return (name[0] == 'a' || name[0] == 'o' ? "an " : "a ") + name;
}

std::string excerpt(const In& v) {
  return quote(v.dump());
}

// Thrown by the parser callback at the depth limit: the parse stops there.
struct TooDeep {};

// nlohmann's message for a parse error quotes the token it read ("last read: '…'", "number
// overflow parsing '…'"): that token is the sender's text, of any length and any bytes (a string
// with invalid UTF-8 in it), so it is cut to its last 80 bytes and escaped like every quote.
std::string describe(const Json::exception& e) {
  std::string_view what = e.what();
  auto open = what.find('\'');
  auto close = what.rfind("'; expected ");
  if (close == std::string_view::npos || close <= open) close = what.rfind('\'');
  if (open == std::string_view::npos || close <= open) return quote(what, 400);
  std::string_view token = what.substr(open + 1, close - open - 1);
  std::string tail =
      token.size() > 80 ? "…" + quote(token.substr(token.size() - 80)) : quote(token);
  return quote(what.substr(0, open + 1), 400) + tail + quote(what.substr(close), 400);
}

Result<In, std::string> parse(std::string_view payload, const PayloadLimits& limits) {
  if (payload.size() > limits.maxBytes)
    return Unexpected{"payload is " + std::to_string(payload.size()) + " bytes, more than " +
                      std::to_string(limits.maxBytes) + " (it begins " + quote(payload) +
                      "); send a smaller payload, or raise the limit with --mqtt-max-payload"};
  In::parser_callback_t depth = [&](int level, In::parse_event_t event, In&) {
    // `level` counts the containers around this one
    if ((event == In::parse_event_t::object_start || event == In::parse_event_t::array_start) &&
        level >= limits.maxDepth)
      throw TooDeep{};
    return true;
  };
  try {
    return In::parse(payload, depth);
  } catch (const TooDeep&) {
    return Unexpected{"payload nests objects and arrays more than " +
                      std::to_string(limits.maxDepth) + " deep (it begins " + quote(payload) +
                      "); send flatter JSON"};
  } catch (const Json::out_of_range& e) {
    // 406: a number beyond a double (1e400) would otherwise be infinity
    return Unexpected{"payload holds a number beyond the range of a double: " + describe(e) +
                      "; send numbers within ±1.7e308 (and within the ranges of the intent)"};
  } catch (const Json::parse_error& e) {
    return Unexpected{"payload is not JSON: " + describe(e)};
  } catch (const Json::exception& e) {
    return Unexpected{"payload cannot be read: " + describe(e)};
  }
}

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> parts;
  while (true) {
    auto slash = s.find('/');
    parts.push_back(s.substr(0, slash));
    if (slash == std::string_view::npos) return parts;
    s.remove_prefix(slash + 1);
  }
}

Result<In, std::string> object(std::string_view payload, const PayloadLimits& limits) {
  auto j = parse(payload, limits);
  if (!j) return j;
  if (!j->is_object()) return Unexpected{"payload must be a JSON object, not " + typeName(*j)};
  return j;
}

}  // namespace detail

std::string quote(std::string_view text, std::size_t maxBytes) {
  std::string out;
  std::size_t i = 0;
  for (; i < text.size() && i < maxBytes;) {
    auto b = static_cast<unsigned char>(text[i]);
    std::size_t n = b < 0x80             ? 1
                    : (b & 0xE0) == 0xC0 ? 2
                    : (b & 0xF0) == 0xE0 ? 3
                    : (b & 0xF8) == 0xF0 ? 4
                                         : 0;
    if (n == 1 && b >= 0x20 && b < 0x7f) {
      out += static_cast<char>(b);
      ++i;
      continue;
    }
    // libmosquitto's check of one character: well formed (no overlong form, no surrogate) and
    // printable (MQTT's rules refuse control characters and non-characters)
    if (n > 1 && i + n <= text.size() && i + n <= maxBytes &&
        mosquitto_validate_utf8(text.data() + i, static_cast<int>(n)) == MOSQ_ERR_SUCCESS) {
      out.append(text.substr(i, n));
      i += n;
      continue;
    }
    out += "\\x" + toHex(std::span<const std::uint8_t>(&b, 1), "");
    ++i;
  }
  if (i < text.size()) out += "…";
  return out;
}

}  // namespace pitwall::topics
