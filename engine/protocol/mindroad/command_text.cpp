// MindRoad instructions written as words (`pitwall encode mindroad …`). Each number is checked
// against its range before it is narrowed into its field.
#include "engine/protocol/mindroad/command_text.hpp"

#include "engine/core/numbers.hpp"

#include <charconv>
#include <optional>
#include <string_view>

namespace pitwall::mindroad {
namespace {

std::optional<long long> parseInteger(std::string_view w) {
  bool negative = !w.empty() && w[0] == '-';
  std::string_view digits = negative ? w.substr(1) : w;
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    digits.remove_prefix(2);
    base = 16;
  }
  long long v = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v, base);
  if (digits.empty() || ec != std::errc{} || end != digits.data() + digits.size())
    return std::nullopt;
  return negative ? -v : v;
}

struct Args {
  std::span<const std::string> words;  // after the instruction's name
  std::string usage;

  Result<long long, std::string> integer(std::size_t i, const std::string& what, long long min,
                                         long long max) const {
    const std::string range = std::to_string(min) + ".." + std::to_string(max);
    if (i >= words.size())
      return Unexpected{"missing " + what + " (" + range + "); usage: " + usage};
    const auto v = parseInteger(words[i]);
    if (!v)
      return Unexpected{what + " '" + words[i] + "' is not a whole number; expected " + range};
    if (*v < min || *v > max)
      return Unexpected{
          outOfRange(what, words[i], static_cast<double>(min), static_cast<double>(max))};
    return *v;
  }
  std::optional<std::string> extra(std::size_t count) const {
    if (words.size() <= count) return std::nullopt;
    return "unexpected '" + words[count] + "' after the arguments; usage: " + usage;
  }
};

}  // namespace

std::vector<std::string> commandForms() {
  return {"stop",
          "contact",
          "steer X Y            (X forward/backward, Y right/left: -128..127)",
          "click X Y            (1..160, 1..120)",
          "buttons NAME|BYTE    (manual, automatic, sensitivity-up, sensitivity-down, or 0..255)",
          "ping",
          "picture-mode rgb|hsv|filter",
          "shutdown"};
}

Result<Instruction, std::string> parseCommand(std::span<const std::string> words) {
  if (words.empty()) return Unexpected{std::string("no instruction given")};
  const std::string& what = words[0];
  auto rest = words.subspan(1);
  auto noArgs = [&](Instruction i) -> Result<Instruction, std::string> {
    if (!rest.empty()) return Unexpected{what + " takes no arguments, got '" + rest[0] + "'"};
    return i;
  };
  if (what == "stop") return noArgs(Stop{});
  if (what == "contact") return noArgs(Contact{});
  if (what == "ping") return noArgs(Ping{});
  if (what == "shutdown") return noArgs(Shutdown{});
  if (what == "steer" || what == "steering") {
    Args a{rest, "steer X Y (-128..127 each)"};
    auto x = a.integer(0, "steer x (forward/backward)", -128, 127);
    if (!x) return Unexpected{x.error()};
    auto y = a.integer(1, "steer y (right/left)", -128, 127);
    if (!y) return Unexpected{y.error()};
    if (auto e = a.extra(2)) return Unexpected{*e};
    return Instruction{Steering{static_cast<std::int8_t>(*x), static_cast<std::int8_t>(*y)}};
  }
  if (what == "click" || what == "mouse-position") {
    Args a{rest, "click X Y (1..160, 1..120)"};
    auto x = a.integer(0, "click x", kClickMinX, kClickMaxX);
    if (!x) return Unexpected{x.error()};
    auto y = a.integer(1, "click y", kClickMinY, kClickMaxY);
    if (!y) return Unexpected{y.error()};
    if (auto e = a.extra(2)) return Unexpected{*e};
    return Instruction{MousePosition{static_cast<std::uint8_t>(*x), static_cast<std::uint8_t>(*y)}};
  }
  if (what == "buttons") {
    Args a{rest,
           "buttons manual|automatic|sensitivity-up|sensitivity-down or a byte 0..255 (bit n: "
           "button n)"};
    if (rest.empty()) return Unexpected{"missing the button; usage: " + a.usage};
    if (auto e = a.extra(1)) return Unexpected{*e};
    if (auto b = buttonFromName(rest[0])) return Instruction{Buttons::fromId(*b)};
    if (!parseInteger(rest[0]))
      return Unexpected{"button '" + rest[0] +
                        "' is unknown; use manual, automatic, sensitivity-up, sensitivity-down "
                        "or a byte 0..255"};
    auto raw = a.integer(0, "buttons byte", 0, 255);
    if (!raw) return Unexpected{raw.error()};
    return Instruction{Buttons{static_cast<std::uint8_t>(*raw)}};
  }
  if (what == "picture-mode") {
    Args a{rest, "picture-mode rgb|hsv|filter (or 0..2)"};
    if (rest.empty()) return Unexpected{"missing the picture mode; usage: " + a.usage};
    if (auto e = a.extra(1)) return Unexpected{*e};
    if (auto p = pictureFromName(rest[0])) return Instruction{PictureMode{*p}};
    if (!parseInteger(rest[0]))
      return Unexpected{"picture mode '" + rest[0] + "' is unknown; use rgb, hsv or filter"};
    auto mode = a.integer(0, "picture mode", 0, 2);
    if (!mode) return Unexpected{mode.error()};
    return Instruction{PictureMode{static_cast<Picture>(*mode)}};
  }
  std::string forms;
  for (const auto& f : commandForms()) forms += "\n  " + f;
  return Unexpected{"unknown instruction '" + what + "'; known:" + forms};
}

}  // namespace pitwall::mindroad
