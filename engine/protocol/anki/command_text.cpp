// Controller→vehicle commands written as words (`pitwall encode anki MESSAGE ARGS…`). Every word
// is checked against its range before it is narrowed into its field, and the finished message
// goes through limits::validate like any other command from the edge.
#include "engine/protocol/anki/command_text.hpp"

#include "engine/core/numbers.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

#include "engine/protocol/anki/limits.hpp"

namespace pitwall::anki {
namespace {

using std::string_view;

// The words after the message name, read left to right. The first problem is kept; reads after it
// return harmless defaults, so a parse function reads straight through without checks.
class Words {
 public:
  Words(std::span<const std::string> words, string_view usage) : words_(words), usage_(usage) {}

  const std::optional<std::string>& error() const { return error_; }
  bool more() const { return !error_ && next_ < words_.size(); }
  bool nextIs(string_view word) const { return more() && words_[next_] == word; }
  void consume() { ++next_; }  // the word nextIs() just matched

  // A required word. `what` names it in the error.
  std::optional<string_view> take(string_view what) {
    if (error_) return std::nullopt;
    if (next_ >= words_.size()) {
      fail(std::string(command()) + " is missing " + std::string(what) +
           "; usage: " + std::string(usage_));
      return std::nullopt;
    }
    return words_[next_++];
  }

  // A whole number (decimal or 0x-hex) in min..max, checked before it is narrowed.
  template <class T>
  T integer(string_view what, long long min, long long max, string_view unit = {}) {
    const auto word = take(what);
    if (!word) return T{};
    const auto value = parseInteger(*word);
    if (!value) {
      fail(quoted(what, *word) + " is not a whole number; expected " + range(min, max, unit));
    } else if (*value < min || *value > max) {
      fail(outOfRange(what, *word, static_cast<double>(min), static_cast<double>(max), unit));
    } else {
      return static_cast<T>(*value);
    }
    return T{};
  }

  // A decimal number of millimetres in min..max (NaN and infinity are out of every range); `why`
  // the range is what it is, said after it when the number is out of it.
  float millimetres(string_view what, double min, double max, string_view why = {}) {
    const auto word = take(what);
    if (!word) return 0;
    double value = 0;
    const auto [end, ec] = std::from_chars(word->data(), word->data() + word->size(), value);
    const std::string expected = formatNumber(min) + ".." + formatNumber(max) + " mm";
    if (word->empty() || end != word->data() + word->size() || ec == std::errc::invalid_argument) {
      fail(quoted(what, *word) + " is not a number; expected " + expected);
    } else if (ec != std::errc{} || !(value >= min && value <= max)) {
      fail(outOfRange(what, *word, min, max, "mm") +
           (why.empty() ? std::string() : " (" + std::string(why) + ")"));
    } else {
      return static_cast<float>(value);
    }
    return 0;
  }

  // One of a few words; its index in `choices`.
  std::size_t choice(string_view what, std::initializer_list<string_view> choices) {
    const auto word = take(what);
    if (!word) return 0;
    std::size_t i = 0;
    for (const auto c : choices) {
      if (*word == c) return i;
      ++i;
    }
    std::string list;
    for (const auto c : choices) (list += list.empty() ? "" : ", ") += c;
    fail(quoted(what, *word) + " is not one of " + list);
    return 0;
  }

  // Refuses whatever is left over.
  void end() {
    if (more()) {
      fail("unexpected word '" + words_[next_] + "' after " + std::string(command()) +
           "; usage: " + std::string(usage_));
    }
  }

  void fail(std::string text) {
    if (!error_) error_ = std::move(text);
  }

 private:
  string_view command() const { return usage_.substr(0, usage_.find(' ')); }

  static std::optional<long long> parseInteger(string_view word) {
    const bool negative = !word.empty() && word.front() == '-';
    if (negative) word.remove_prefix(1);
    int base = 10;
    if (word.size() > 2 && word[0] == '0' && (word[1] == 'x' || word[1] == 'X')) {
      word.remove_prefix(2);
      base = 16;
    }
    if (word.empty() || word.front() == '-' || word.front() == '+') return std::nullopt;
    unsigned long long magnitude = 0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), magnitude, base);
    if (end != word.data() + word.size()) return std::nullopt;
    // Too big for 64 bits is out of every range; say so rather than "not a number".
    constexpr auto kHuge = static_cast<unsigned long long>(1) << 62;
    if (ec == std::errc::result_out_of_range || magnitude > kHuge) magnitude = kHuge;
    const auto v = static_cast<long long>(magnitude);
    return negative ? -v : v;
  }

  static std::string withUnit(std::string text, string_view unit) {
    if (!unit.empty()) (text += ' ') += unit;
    return text;
  }
  static std::string range(long long min, long long max, string_view unit) {
    return std::to_string(min) + ".." + withUnit(std::to_string(max), unit);
  }
  static std::string quoted(string_view what, string_view word) {
    return std::string(what) + " '" + std::string(word) + "'";
  }

  std::span<const std::string> words_;
  string_view usage_;
  std::size_t next_ = 1;  // words_[0] is the message name
  std::optional<std::string> error_;
};

constexpr int kByte = 255;

Message sdkMode(Words& w) {
  SdkMode m;
  m.on = w.choice("sdk-mode state", {"off", "on"}) == 1;
  if (w.more()) m.flags = w.integer<std::uint8_t>("flags", 0, kByte);
  return m;
}

// drive-sdk's own example sends accel 25000 with speed 1000; we default to a gentler 1000.
Message setSpeed(Words& w) {
  SetSpeed m;
  m.speed_mm_s = w.integer<std::int16_t>("speed", limits::kSpeedMin, limits::kSpeedMax, "mm/s");
  m.accel_mm_s2 = 1000;
  if (w.more() && !w.nextIs("respect-limit")) {
    m.accel_mm_s2 =
        w.integer<std::int16_t>("acceleration", limits::kAccelMin, limits::kAccelMax, "mm/s²");
  }
  if (w.nextIs("respect-limit")) {
    m.respect_limit = true;
    w.consume();
  }
  return m;
}

// seed 000 §4.3.4.4, as limits::validate says it.
constexpr string_view kOffRoad = "beyond it the car leaves the road";

Message changeLane(Words& w) {
  ChangeLane m;
  m.h_speed_mm_s = w.integer<std::uint16_t>("lane-change speed", limits::kLaneSpeedMin,
                                            limits::kLaneSpeedMax, "mm/s");
  m.h_accel_mm_s2 = w.integer<std::uint16_t>("lane-change acceleration", limits::kLaneAccelMin,
                                             limits::kLaneAccelMax, "mm/s²");
  m.offset_mm = w.millimetres("offset", limits::kOffsetMin, limits::kOffsetMax, kOffRoad);
  if (w.more()) {  // HOP and TAG come together
    m.hop_intent = w.integer<std::uint8_t>("hop intent", 0, kByte);
    m.tag = w.integer<std::uint8_t>("tag", 0, kByte);
  }
  return m;
}

Message setOffset(Words& w) {
  return SetOffset{.offset_mm =
                       w.millimetres("offset", limits::kOffsetMin, limits::kOffsetMax, kOffRoad)};
}

// Word order follows TurnType's values: none 0, left 1, right 2, uturn 3, uturn-jump 4.
Message turn(Words& w) {
  Turn m;
  m.type = static_cast<TurnType>(
      w.choice("turn type", {"none", "left", "right", "uturn", "uturn-jump"}));
  if (w.more()) {
    m.trigger = static_cast<TurnTrigger>(w.choice("turn trigger", {"immediate", "intersection"}));
  }
  return m;
}

Message lights(Words& w) {
  return SetLights{.mask = w.integer<std::uint8_t>("mask", 0, kByte)};
}

// Up to 3 groups of 5 words; unused channel slots stay zero (the frame is always size 17).
Message lightsPattern(Words& w) {
  LightsPattern m;
  do {
    if (m.channel_count == m.channels.size()) {
      w.fail("lights-pattern takes at most " + std::to_string(m.channels.size()) +
             " channels (5 words each); the 4th starts at '" +
             std::string(w.take("channel").value_or("")) + "'");
      break;
    }
    auto& c = m.channels[m.channel_count++];
    const std::string slot = "slot " + std::to_string(m.channel_count) + " ";
    c.channel = w.integer<std::uint8_t>(slot + "channel", 0, limits::kLightChannelMax);
    c.effect = w.integer<std::uint8_t>(slot + "effect", 0, limits::kLightEffectMax);
    c.start = w.integer<std::uint8_t>(slot + "start intensity", 0, limits::kLightIntensityMax);
    c.end = w.integer<std::uint8_t>(slot + "end intensity", 0, limits::kLightIntensityMax);
    c.cycles_per_10s = w.integer<std::uint8_t>(slot + "cycles per 10 s", 0, kByte);
  } while (w.more());
  return m;
}

Message config(Words& w) {
  SetConfig m;
  m.super_code_parse_mask = w.integer<std::uint8_t>("parse mask", 0, kByte);
  // anki-overdrive.md: track material 0 plastic, 1 vinyl.
  m.track_material =
      static_cast<std::uint8_t>(w.choice("track material", {"plastic", "vinyl", "0", "1"}) % 2);
  return m;
}

struct Form {
  string_view name;
  string_view usage;
  Message (*parse)(Words&);
  string_view alias = {};  // the codec's name for it, also accepted
};

constexpr Form kForms[] = {
    {"sdk-mode", "sdk-mode on|off [FLAGS]", sdkMode},
    {"set-speed", "set-speed SPEED [ACCEL] [respect-limit]", setSpeed},
    {"change-lane", "change-lane HSPEED HACCEL OFFSET [HOP TAG]", changeLane},
    {"set-offset", "set-offset OFFSET", setOffset},
    {"cancel-lane-change", "cancel-lane-change",
     [](Words&) -> Message { return CancelLaneChange{}; }},
    {"turn", "turn left|right|uturn|uturn-jump|none [immediate|intersection]", turn},
    {"ping", "ping", [](Words&) -> Message { return PingRequest{}; }, "ping-request"},
    {"version", "version", [](Words&) -> Message { return VersionRequest{}; }, "version-request"},
    {"battery", "battery", [](Words&) -> Message { return BatteryRequest{}; }, "battery-request"},
    {"disconnect", "disconnect", [](Words&) -> Message { return Disconnect{}; }},
    {"lights", "lights MASK", lights, "set-lights"},
    {"lights-pattern",
     "lights-pattern CHANNEL EFFECT START END CYCLES [CHANNEL EFFECT START END CYCLES]…",
     lightsPattern},
    {"config", "config PARSE_MASK plastic|vinyl|0|1", config, "set-config"},
};

std::string knownNames() {
  std::string list;
  for (const auto& f : kForms) (list += list.empty() ? "" : ", ") += f.name;
  return list;
}

}  // namespace

Result<Message, std::string> parseCommand(std::span<const std::string> words) {
  if (words.empty()) return Unexpected{"no message given; known messages: " + knownNames()};
  for (const auto& form : kForms) {
    if (words[0] != form.name && (form.alias.empty() || words[0] != form.alias)) continue;
    Words w(words, form.usage);
    Message message = form.parse(w);
    w.end();
    if (w.error()) return Unexpected{*w.error()};
    if (auto refused = limits::validate(message)) return Unexpected{*refused};
    return message;
  }
  return Unexpected{"unknown message '" + words[0] + "'; known messages: " + knownNames()};
}

std::vector<std::string> commandForms() {
  std::vector<std::string> forms;
  for (const auto& f : kForms) forms.emplace_back(f.usage);
  return forms;
}

}  // namespace pitwall::anki
