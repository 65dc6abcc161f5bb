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

// A link line's "link": {"up":bool,"reason":"…","writeFailures":n,"stalls":n,"rssi":n|null}
// (connects and drops may be there too: what the run counted; a replay counts them again).
std::variant<RecordedFrame, std::string> parseLink(const json& link, RecordedFrame frame) {
  if (!link.is_object()) return "\"link\" is not an object: " + shown(link);
  auto up = link.find("up");
  if (up == link.end() || !up->is_boolean())
    return "\"link\" needs \"up\", true or false: " + shown(link);
  RecordedFrame::Link l;
  l.up = up->get<bool>();
  if (auto reason = link.find("reason"); reason != link.end() && !reason->is_null()) {
    if (!reason->is_string()) return "\"link\".\"reason\" is not a string: " + shown(*reason);
    l.reason = printable(reason->get_ref<const std::string&>(), kMaxRecordedName * 4);
  }
  auto count = [&](const char* name, int& out) -> std::optional<std::string> {
    auto v = link.find(name);
    if (v == link.end() || v->is_null()) return std::nullopt;
    if (!v->is_number_integer() || v->get<std::int64_t>() < 0 ||
        v->get<std::int64_t>() > 1'000'000'000)
      return "\"link\".\"" + std::string(name) + "\" must be a count 0..1000000000, not " +
             shown(*v);
    out = static_cast<int>(v->get<std::int64_t>());
    return std::nullopt;
  };
  if (auto why = count("writeFailures", l.writeFailures)) return *why;
  if (auto why = count("stalls", l.stalls)) return *why;
  if (auto rssi = link.find("rssi"); rssi != link.end() && !rssi->is_null()) {
    if (!rssi->is_number_integer() || rssi->get<std::int64_t>() < -127 ||
        rssi->get<std::int64_t>() > 20)
      return "\"link\".\"rssi\" must be dBm, an integer -127..20, not " + shown(*rssi);
    l.rssi = static_cast<int>(rssi->get<std::int64_t>());
  }
  frame.link = std::move(l);
  return frame;
}

}  // namespace

std::string lineTooLong(std::size_t length) {
  return "a line of " + std::to_string(length) + " bytes, longer than " +
         std::to_string(kMaxLineBytes) + ": not a frame of a record";
}

LineReader::LineReader(std::istream& in) : in_(in), buffer_(kMaxLineBytes + 1, '\0') {}

void LineReader::restart() {
  number_ = 0;
  end_ = !in_;
}

LineReader::Got LineReader::next(std::string_view& line, std::size_t& tooLong) {
  if (end_) return Got::End;
  ++number_;
  in_.getline(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  const auto got = static_cast<std::size_t>(in_.gcount());
  if ((in_.eof() && got == 0) || in_.bad()) {
    end_ = true;
    return Got::End;
  }
  if (in_.fail() && !in_.eof()) {  // longer than the buffer: skipped unread
    in_.clear();
    in_.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    tooLong = got + static_cast<std::size_t>(in_.gcount()) - (in_.eof() ? 0 : 1);
    end_ = in_.eof();
    return Got::TooLong;
  }
  end_ = in_.eof();
  line = std::string_view(buffer_.data(), got - (in_.eof() ? 0 : 1));  // without the newline
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return Got::Line;
}

std::variant<RecordedFrame, std::string> parseRecordLine(std::string_view line, double lastTime,
                                                         bool timed) {
  if (line.size() > kMaxLineBytes) return lineTooLong(line.size());
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
  if (t == j.end() && !timed) t = j.emplace("t", 0).first;  // its time is worked out later
  if (t == j.end()) return std::string("no \"t\" (the frame's time in seconds)");
  if (!t->is_number()) return "\"t\" is not a number: " + shown(*t);
  frame.t = t->get<double>();
  if (!std::isfinite(frame.t) || frame.t < 0 || frame.t > kMaxRecordedTime)
    return outOfRange("\"t\"", shown(*t), 0, kMaxRecordedTime, "seconds");
  if (frame.t < lastTime - kBackwardsSlack)
    return "\"t\" " + shown(*t) + " goes back in time (the frame before was at " +
           shown(json(lastTime)) + ")";

  // The race as the race library reported it (pitwall.view.race), for a replay's view: kept as
  // its text, never read here (the page reads it as it reads a live race's).
  if (auto race = j.find("race"); race != j.end() && j.find("car") == j.end()) {
    if (!race->is_object() && !race->is_null()) return "\"race\" is not an object: " + shown(*race);
    frame.race = race->dump(-1, ' ', false, json::error_handler_t::replace);
    return frame;
  }

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

  if (auto link = j.find("link"); link != j.end() && j.find("dir") == j.end())
    return parseLink(*link, std::move(frame));

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

void BadLines::add(BadLine bad) {
  ++count;
  if (keep == 0) return;
  if (first.size() >= keep && bad.line > first.back().line) return;
  auto at = std::upper_bound(first.begin(), first.end(), bad.line,
                             [](std::size_t l, const BadLine& b) { return l < b.line; });
  first.insert(at, std::move(bad));
  if (first.size() > keep) first.pop_back();
}

RecordStream::RecordStream(std::istream& in, std::size_t keepBad) : in_(in), lines_(in) {
  bad_.keep = keepBad;
}

bool RecordStream::rewind() {
  in_.clear();
  in_.seekg(0);
  lines_.restart();
  end_ = !in_;
  lastTime_ = before_ = 0;
  pending_.reset();
  const std::size_t keep = bad_.keep;
  bad_ = BadLines{};
  bad_.keep = keep;
  return !end_;
}

std::optional<RecordedFrame> RecordStream::parseNext(std::size_t& lines) {
  while (!end_) {
    if (lines == 0) return std::nullopt;  // not the end: more another time
    --lines;
    std::string_view line;
    std::size_t length = 0;
    const LineReader::Got got = lines_.next(line, length);
    if (got == LineReader::Got::End) break;
    end_ = lines_.atEnd();
    if (got == LineReader::Got::TooLong) {
      bad_.add({lines_.number(), lineTooLong(length)});
      continue;
    }
    if (line.find_first_not_of(" \t") == line.npos) continue;
    auto parsed = parseRecordLine(line, 0);  // the time's order is checked by next()
    if (auto* frame = std::get_if<RecordedFrame>(&parsed)) {
      frame->line = lines_.number();
      return std::move(*frame);
    }
    bad_.add({lines_.number(), std::move(std::get<std::string>(parsed))});
  }
  end_ = true;
  return std::nullopt;
}

std::optional<RecordedFrame> RecordStream::next(std::size_t lines) {
  for (;;) {
    auto frame = parseNext(lines);
    if (!frame && !end_) return std::nullopt;  // the lines ran out first
    if (!frame) {                              // the end: the frame held back is the last
      auto last = std::move(pending_);
      pending_.reset();
      return last;
    }
    if (frame->t < lastTime_ - kBackwardsSlack) {
      // One frame from far ahead (an edited or damaged time) must not take every frame after
      // it: when this one follows the frame before that one, that one is the odd one out.
      if (pending_ && frame->t >= before_ - kBackwardsSlack && pending_->t - frame->t > kOddJump) {
        bad_.add({pending_->line, "\"t\" " + timeText(pending_->t) +
                                      " lies ahead of the frames around it (the next is at " +
                                      timeText(frame->t) + ")"});
        pending_.reset();
        lastTime_ = before_;
      } else {
        bad_.add({frame->line, "\"t\" " + timeText(frame->t) +
                                   " goes back in time (the frame before was at " +
                                   timeText(lastTime_) + ")"});
        continue;
      }
    }
    lastTime_ = std::max(lastTime_, frame->t);
    auto out = std::move(pending_);
    pending_ = std::move(frame);
    if (out) {
      before_ = out->t;
      return out;
    }
  }
}

Record readRecord(std::istream& in) {
  Record record;
  RecordStream stream(in, std::numeric_limits<std::size_t>::max());
  while (auto frame = stream.next()) {
    if (frame->car == 0) {
      record.races.push_back(std::move(*frame));
      continue;
    }
    if (frame->link) {
      record.links.push_back(std::move(*frame));
      continue;
    }
    if (!frame->name.empty()) record.names.emplace(frame->car, frame->name);
    if (record.layout.empty()) record.layout = frame->layout;
    record.frames.push_back(std::move(*frame));
  }
  record.bad = stream.bad().first;
  return record;
}

RecordSummary scanRecord(std::istream& in) {
  RecordSummary summary;
  RecordStream stream(in, summary.bad.keep);
  while (auto frame = stream.next()) {
    summary.duration = std::max(summary.duration, frame->t);
    if (frame->car == 0) {  // a race line: no car's
      ++summary.raceLines;
      continue;
    }
    if (frame->link) {  // a link line: no frame
      if (!frame->link->up) ++summary.drops[frame->car];
      summary.framesOut.try_emplace(frame->car, 0);
      continue;
    }
    ++summary.frames;
    summary.framesOut[frame->car] += frame->tx ? 1 : 0;
    if (!frame->name.empty()) summary.names.emplace(frame->car, frame->name);
    if (summary.layout.empty()) summary.layout = std::move(frame->layout);
  }
  summary.bad = stream.bad();
  return summary;
}

}  // namespace pitwall
