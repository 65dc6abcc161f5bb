#include "engine/record/record_reader.hpp"

#include "engine/core/numbers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "engine/core/hex.hpp"
#include "engine/core/printable.hpp"

namespace pitwall {

namespace {

using nlohmann::json;

std::string shown(const json& value) {
  return printable(value.dump(-1, ' ', false, json::error_handler_t::replace), 80);
}

// nlohmann's "[json.exception.parse_error.101] parse error at line 1, column 5: syntax error
// while parsing value - invalid literal; last read: '{x'" → "column 5: invalid literal; last
// read: '{x'".
std::string parseErrorText(std::string what) {
  if (auto end = what.find("] "); what.rfind("[json.exception", 0) == 0 && end != what.npos)
    what.erase(0, end + 2);
  if (what.rfind("parse error at line 1, ", 0) == 0) what.erase(0, 23);
  if (auto at = what.find("syntax error while parsing "); at != what.npos) {
    auto dash = what.find(" - ", at);
    if (dash != what.npos) what.erase(at, dash + 3 - at);
  }
  return printable(what, 160);
}

// A first pass that builds nothing: syntax, UTF-8 and how deep the document nests. Only a line
// that passes is parsed into a json value (whose construction and destruction recurse).
class Check : public nlohmann::json_sax<json> {
 public:
  std::string error;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return deeper(); }
  bool key(string_t&) override { return true; }
  bool end_object() override { return --depth_, true; }
  bool start_array(std::size_t) override { return deeper(); }
  bool end_array() override { return --depth_, true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    error = "not JSON: " + parseErrorText(e.what());
    return false;
  }

 private:
  int depth_ = 0;
  bool deeper() {
    if (++depth_ <= kMaxJsonDepth) return true;
    error =
        "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels: not a frame of a record";
    return false;
  }
};

// The frame's bytes: pairs of hex digits, separated by spaces or not ("06 24 e8", "0624e8").
std::variant<std::vector<std::uint8_t>, std::string> hexBytes(const std::string& text) {
  std::string digits;
  digits.reserve(text.size());
  for (char c : text)
    if (c != ' ') digits += c;
  if (digits.empty()) return std::string("\"hex\" is empty: no frame");
  auto bytes = fromHex(digits);
  if (!bytes) return "\"hex\": " + printable(bytes.error(), 80);
  return std::move(*bytes);
}

}  // namespace

std::variant<RecordedFrame, std::string> parseRecordLine(std::string_view line, double lastTime) {
  if (line.size() > kMaxLineBytes)
    return "a line of " + std::to_string(line.size()) + " bytes, longer than " +
           std::to_string(kMaxLineBytes) + ": not a frame of a record";
  Check check;
  if (!json::sax_parse(line, &check) || !check.error.empty())
    return check.error.empty() ? std::string("not JSON") : check.error;
  json j;
  try {
    j = json::parse(line);
  } catch (const json::exception& e) {  // the check above let it through: never, but not a crash
    return "not JSON: " + parseErrorText(e.what());
  }
  if (!j.is_object()) return "not a JSON object but " + printable(j.type_name(), 80);

  RecordedFrame frame;
  auto t = j.find("t");
  if (t == j.end()) return std::string("no \"t\" (the frame's time in seconds)");
  if (!t->is_number()) return "\"t\" is not a number: " + shown(*t);
  frame.t = t->get<double>();
  if (!std::isfinite(frame.t) || frame.t < 0 || frame.t > kMaxRecordedTime)
    return outOfRange("\"t\"", shown(*t), 0, kMaxRecordedTime, "seconds");
  if (frame.t < lastTime - kBackwardsSlack)
    return "\"t\" " + shown(*t) + " goes back in time (the frame before was at " +
           shown(json(lastTime)) + ")";

  auto car = j.find("car");
  if (car == j.end()) return std::string("no \"car\" (the car's number)");
  const bool inRange =
      (car->is_number_unsigned() && car->get<std::uint64_t>() >= 1 &&
       car->get<std::uint64_t>() <= static_cast<std::uint64_t>(kMaxRecordedCar)) ||
      (car->is_number_integer() && !car->is_number_unsigned() && car->get<std::int64_t>() >= 1 &&
       car->get<std::int64_t>() <= kMaxRecordedCar);
  if (!inRange)
    return "\"car\" must be an integer 1.." + std::to_string(kMaxRecordedCar) + ", not " +
           shown(*car);
  frame.car = car->get<int>();

  auto dir = j.find("dir");
  if (dir == j.end()) return std::string("no \"dir\" (\"rx\" or \"tx\")");
  if (!dir->is_string() || (*dir != "rx" && *dir != "tx"))
    return "\"dir\" must be \"rx\" or \"tx\", not " + shown(*dir);
  frame.tx = *dir == "tx";

  auto hex = j.find("hex");
  if (hex == j.end()) return std::string("no \"hex\" (the frame's bytes)");
  if (!hex->is_string()) return "\"hex\" is not a string: " + shown(*hex);
  auto bytes = hexBytes(hex->get_ref<const std::string&>());
  if (auto* why = std::get_if<std::string>(&bytes)) return *why;
  frame.bytes = std::move(std::get<std::vector<std::uint8_t>>(bytes));
  // what a replay is told beside the frames; anything else in them is not a frame's business
  auto plain = [](const std::string& s) {  // no control character reaches a log or terminal
    return std::none_of(s.begin(), s.end(),
                        [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
  };
  if (auto name = j.find("carName");
      name != j.end() && name->is_string() &&
      name->get_ref<const std::string&>().size() <= kMaxRecordedName &&
      plain(name->get_ref<const std::string&>()))
    frame.name = name->get<std::string>();
  if (auto layout = j.find("layout");
      layout != j.end() && layout->is_string() &&
      layout->get_ref<const std::string&>().size() <= kMaxRecordedLayout)
    frame.layout = layout->get<std::string>();
  return frame;
}

namespace {
// How far ahead of the next frame a frame must lie to be taken for the odd one out, not the
// next for a frame that went back: a jump, not jitter.
constexpr double kOddJump = 1.0;

std::string timeText(double t) {
  return shown(json(t));
}
}  // namespace

Record readRecord(std::istream& in) {
  Record record;
  std::string buffer(kMaxLineBytes + 1, '\0');
  double lastTime = 0;
  for (std::size_t number = 1;; ++number) {
    in.getline(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (in.eof() && got == 0) break;
    if (in.fail() && !in.eof()) {  // longer than the buffer: skipped unread
      in.clear();
      in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
      std::size_t length = got + static_cast<std::size_t>(in.gcount()) - (in.eof() ? 0 : 1);
      record.bad.push_back({number, "a line of " + std::to_string(length) + " bytes, longer than " +
                                        std::to_string(kMaxLineBytes) +
                                        ": not a frame of a record"});
      if (in.eof()) break;
      continue;
    }
    std::string_view line(buffer.data(), got - (in.eof() ? 0 : 1));  // without the newline
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") == line.npos) {
      if (in.eof()) break;
      continue;
    }
    auto parsed = parseRecordLine(line, 0);  // the time's order is checked here, below
    if (auto* frame = std::get_if<RecordedFrame>(&parsed)) {
      frame->line = number;
      if (frame->t < lastTime - kBackwardsSlack) {
        // One frame from far ahead (an edited or damaged time) must not take every frame after
        // it: when this one follows the frame before that one, that one is the odd one out.
        auto& frames = record.frames;
        const double before = frames.size() >= 2 ? frames[frames.size() - 2].t : 0;
        if (!frames.empty() && frame->t >= before - kBackwardsSlack &&
            frames.back().t - frame->t > kOddJump) {
          BadLine odd{frames.back().line, "\"t\" " + timeText(frames.back().t) +
                                              " lies ahead of the frames around it (the next is "
                                              "at " +
                                              timeText(frame->t) + ")"};
          auto at = std::upper_bound(record.bad.begin(), record.bad.end(), odd.line,
                                     [](std::size_t l, const BadLine& b) { return l < b.line; });
          record.bad.insert(at, std::move(odd));
          frames.pop_back();
          lastTime = frames.empty() ? 0 : std::max(before, frames.back().t);
        } else {
          record.bad.push_back({number, "\"t\" " + timeText(frame->t) +
                                            " goes back in time (the frame before was at " +
                                            timeText(lastTime) + ")"});
          if (in.eof()) break;
          continue;
        }
      }
      lastTime = std::max(lastTime, frame->t);
      if (!frame->name.empty()) record.names.emplace(frame->car, frame->name);
      if (record.layout.empty()) record.layout = frame->layout;
      record.frames.push_back(std::move(*frame));
    } else {
      record.bad.push_back({number, std::move(std::get<std::string>(parsed))});
    }
    if (in.eof()) break;
  }
  return record;
}

}  // namespace pitwall
