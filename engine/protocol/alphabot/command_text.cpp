#include "engine/protocol/alphabot/command_text.hpp"

#include "engine/core/numbers.hpp"

#include <charconv>
#include <limits>
#include <string_view>

#include "engine/protocol/alphabot/toggles.hpp"

namespace pitwall::alphabot {
namespace {

struct Form {
  const char* name;
  const char* args;
};
constexpr Form kForms[] = {
    {"drive", "SPEED STEER (-128..127 each; negative: backwards / left)"},
    {"measure-distance", "DEGREE (-360..360, relative to the heading)"},
    {"calibrate-steering", ""},
    {"calibrate-compass", ""},
    {"toggles", "NAME[,NAME…] or none (names: see below)"},
    {"ping", "TIME (a signed 64-bit number)"},
    {"anchor", "ID X Y (id 0..255, cm -32768..32767)"},
    {"navigate", "X Y (cm)"},
    {"add-obstacle", "X Y WIDTH HEIGHT (cm; width and height 1..65535)"},
    {"remove-obstacle", "ID (0..255)"},
    {"remove-obstacle-at", "X Y (cm)"},
    {"clear-obstacles", ""},
};

struct Parser {
  const std::vector<std::string>& words;
  std::string error;

  bool number(std::size_t i, const char* what, long long lo, long long hi, long long& out) {
    if (i >= words.size()) {
      error = std::string("missing ") + what;
      return false;
    }
    std::string_view s = words[i];
    bool negative = !s.empty() && s[0] == '-';
    std::string_view digits = negative ? s.substr(1) : s;
    int base = 10;
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
      digits.remove_prefix(2);
      base = 16;
    }
    unsigned long long magnitude = 0;
    auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude, base);
    if (digits.empty() || ec == std::errc::invalid_argument ||
        end != digits.data() + digits.size()) {
      error = std::string(what) + " '" + std::string(s) + "' is not a whole number";
      return false;
    }
    constexpr auto kMax = static_cast<unsigned long long>(std::numeric_limits<long long>::max());
    if (ec == std::errc::result_out_of_range || magnitude > kMax + (negative ? 1 : 0)) {
      error = outOfRange(what, s, static_cast<double>(lo), static_cast<double>(hi));
      return false;
    }
    out = negative ? static_cast<long long>(0ULL - magnitude) : static_cast<long long>(magnitude);
    error = checkRange(what, out, lo, hi);
    return error.empty();
  }
};

}  // namespace

std::string checkRange(const char* what, long long value, long long lo, long long hi) {
  if (value >= lo && value <= hi) return {};
  return outOfRange(what, std::to_string(value), static_cast<double>(lo), static_cast<double>(hi));
}

std::vector<std::string> commandForms() {
  std::vector<std::string> out;
  for (const auto& f : kForms) out.push_back(std::string(f.name) + (*f.args ? " " : "") + f.args);
  out.push_back("toggle names: " + toggleNames());
  return out;
}

Result<Request, std::string> parseRequest(const std::vector<std::string>& words) {
  if (words.empty()) return Unexpected{std::string("no message given")};
  const std::string& cmd = words[0];
  const Form* form = nullptr;
  for (const auto& f : kForms)
    if (cmd == f.name) form = &f;
  if (!form) {
    std::string names;
    for (const auto& f : kForms) names += (names.empty() ? "" : ", ") + std::string(f.name);
    return Unexpected{"unknown alphabot message '" + cmd + "'; known: " + names};
  }
  Parser p{words, {}};
  long long a = 0, b = 0, c = 0, d = 0;
  auto fail = [&]() {
    return Unexpected{cmd + ": " + p.error + " (usage: " + cmd + " " + form->args + ")"};
  };
  std::size_t want = 1;
  Request request;
  if (cmd == "drive") {
    if (!p.number(1, "speed", kDriveMin, kDriveMax, a) ||
        !p.number(2, "steer", kDriveMin, kDriveMax, b))
      return fail();
    request = Drive{static_cast<std::int8_t>(a), static_cast<std::int8_t>(b)};
    want = 3;
  } else if (cmd == "measure-distance") {
    if (!p.number(1, "degree", kDegreeMin, kDegreeMax, a)) return fail();
    request = MeasureDistance{static_cast<std::int16_t>(a)};
    want = 2;
  } else if (cmd == "calibrate-steering") {
    request = CalibrateSteering{};
  } else if (cmd == "calibrate-compass") {
    request = CalibrateCompass{};
  } else if (cmd == "toggles") {
    // Names separated by commas and/or spaces; "none" clears every bit.
    Toggles t;
    if (words.size() < 2) {
      p.error = "missing toggle names";
      return fail();
    }
    for (std::size_t i = 1; i < words.size(); ++i) {
      std::string_view rest = words[i];
      while (!rest.empty()) {
        auto comma = rest.find(',');
        std::string_view name = rest.substr(0, comma);
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
        if (name.empty() || name == "none") continue;
        const ToggleBit* bit = findToggle(name);
        if (!bit) {
          p.error = "unknown toggle '" + std::string(name) + "'; known: " + toggleNames();
          return fail();
        }
        setBit(t, *bit, true);
      }
    }
    request = SetToggles{t};
    want = words.size();
  } else if (cmd == "ping") {
    if (!p.number(1, "time", std::numeric_limits<long long>::min(),
                  std::numeric_limits<long long>::max(), a))
      return fail();
    request = Ping{a};
    want = 2;
  } else if (cmd == "anchor") {
    if (!p.number(1, "anchor id", kIdMin, kIdMax, a) ||
        !p.number(2, "x (cm)", kCoordMin, kCoordMax, b) ||
        !p.number(3, "y (cm)", kCoordMin, kCoordMax, c))
      return fail();
    request = SetAnchor{static_cast<std::uint8_t>(a), static_cast<std::int16_t>(b),
                        static_cast<std::int16_t>(c)};
    want = 4;
  } else if (cmd == "navigate" || cmd == "remove-obstacle-at") {
    if (!p.number(1, "x (cm)", kCoordMin, kCoordMax, a) ||
        !p.number(2, "y (cm)", kCoordMin, kCoordMax, b))
      return fail();
    if (cmd == "navigate")
      request = NavigateTo{static_cast<std::int16_t>(a), static_cast<std::int16_t>(b)};
    else
      request = RemoveObstacleAt{static_cast<std::int16_t>(a), static_cast<std::int16_t>(b)};
    want = 3;
  } else if (cmd == "add-obstacle") {
    if (!p.number(1, "x (cm)", kCoordMin, kCoordMax, a) ||
        !p.number(2, "y (cm)", kCoordMin, kCoordMax, b) ||
        !p.number(3, "width (cm)", kSizeMin, kSizeMax, c) ||
        !p.number(4, "height (cm)", kSizeMin, kSizeMax, d))
      return fail();
    request = AddObstacle{static_cast<std::int16_t>(a), static_cast<std::int16_t>(b),
                          static_cast<std::uint16_t>(c), static_cast<std::uint16_t>(d)};
    want = 5;
  } else if (cmd == "remove-obstacle") {
    if (!p.number(1, "obstacle id", kIdMin, kIdMax, a)) return fail();
    request = RemoveObstacleById{static_cast<std::uint8_t>(a)};
    want = 2;
  } else {
    request = ClearObstacles{};
  }
  if (words.size() > want) {
    p.error = "unexpected extra argument '" + words[want] + "'";
    return fail();
  }
  return request;
}

}  // namespace pitwall::alphabot
