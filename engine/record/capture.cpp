#include "engine/record/capture.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <variant>
#include <vector>

#include "engine/core/hex.hpp"
#include "engine/core/printable.hpp"
#include "engine/protocol/anki/codec.hpp"

namespace pitwall {

namespace {

bool blank(std::string_view line) {
  return line.find_first_not_of(" \t") == line.npos;
}

bool digitsOnly(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The next line that is not blank; one too long is skipped, and added to `bad` when given.
bool nextLine(LineReader& lines, std::string_view& line, BadLines* bad) {
  for (;;) {
    std::size_t length = 0;
    switch (lines.next(line, length)) {
      case LineReader::Got::End:
        return false;
      case LineReader::Got::TooLong:
        if (bad) bad->add({lines.number(), lineTooLong(length)});
        break;
      case LineReader::Got::Line:
        if (!blank(line)) return true;
        break;
    }
  }
}

struct CaptureLine {
  std::string car;
  std::vector<std::uint8_t> bytes;
};

// `INDEX CAR HEX…`: an index (an order, not a time), the car's name, the frame's bytes as pairs
// of hex digits.
std::variant<CaptureLine, std::string> parseCaptureLine(std::string_view line) {
  std::istringstream words{std::string(line)};
  std::string index, car, word, digits;
  words >> index >> car;
  if (!digitsOnly(index))
    return "not a line of a capture (INDEX CAR HEX…): " + printable(std::string(line), 80);
  if (car.empty()) return std::string("no car after the index (INDEX CAR HEX…)");
  while (words >> word) digits += word;
  if (digits.empty()) return "no frame after the car " + printable(car, 40);
  auto bytes = fromHex(digits);
  if (!bytes) return "the frame: " + printable(bytes.error(), 80);
  return CaptureLine{std::move(car), std::move(*bytes)};
}

// A reported speed below this is a car standing: it tells no piece's time.
constexpr double kSlowest = 10;  // mm/s
// No piece takes longer (a speed misread as 10 mm/s would make a piece take minutes).
constexpr double kLongestPiece = 60;  // s

// The times of one car's frames, in its order, from its own reports: into `times`, by frame.
class CarClock {
 public:
  explicit CarClock(std::vector<double>& times) : times_(times) {}

  void add(std::size_t frame, const std::vector<std::uint8_t>& bytes, bool tx) {
    members_.push_back(frame);
    if (tx) return;  // a command says nothing of where the car is
    auto m = anki::decode(bytes);
    if (!m) return;  // the replay counts it as malformed
    if (auto* p = std::get_if<anki::PositionUpdate>(&*m)) {
      if (p->speed_mm_s > 0) {
        speedSum_ += p->speed_mm_s;
        ++speeds_;
      }
    } else if (auto* s = std::get_if<anki::SpeedUpdate>(&*m)) {
      // what the car was told: the speed of a piece with no position update until one says more
      const int said = s->actual_mm_s && *s->actual_mm_s > 0 ? *s->actual_mm_s : s->desired_mm_s;
      if (said > 0 && speed_ <= 0) speed_ = said;
    } else if (auto* t = std::get_if<anki::TransitionUpdate>(&*m)) {
      transition(t->left_wheel_distance_cm, t->right_wheel_distance_cm);
    }
  }

  // The frames after the car's last transition: as far apart as those of its last piece.
  void finish() {
    for (std::size_t i = 0; i < members_.size(); ++i)
      times_[members_[i]] = now_ + gap_ * static_cast<double>(i + 1);
    members_.clear();
  }

  std::size_t inferred() const { return inferred_; }

 private:
  void transition(int leftCm, int rightCm) {
    const double distance = (leftCm + rightCm) * 5.0;  // mm: the mean of the wheels'
    const double speed = speeds_ > 0 ? speedSum_ / speeds_ : speed_;
    double duration = kCaptureGap * static_cast<double>(members_.size());
    // The first transition ends a piece the car was put on somewhere: its distance is not the
    // time since the first frame.
    if (seen_ && distance > 0 && speed >= kSlowest) {
      duration = std::min(distance / speed, kLongestPiece);
      inferred_ += members_.size();
      speed_ = speed;
    }
    const double n = static_cast<double>(members_.size());
    for (std::size_t i = 0; i < members_.size(); ++i)
      times_[members_[i]] = now_ + duration * static_cast<double>(i + 1) / n;
    gap_ = duration / n;
    now_ += duration;
    members_.clear();
    speedSum_ = 0;
    speeds_ = 0;
    seen_ = true;
  }

  std::vector<double>& times_;
  std::vector<std::size_t> members_;  // frames since the last transition, the next one's last
  double now_ = 0;                    // the time of the last transition
  double gap_ = kCaptureGap;
  double speed_ = 0;  // mm/s: the last piece's, or what a speed update said
  double speedSum_ = 0;
  int speeds_ = 0;
  bool seen_ = false;
  std::size_t inferred_ = 0;
};

std::string seconds(double t) {
  char text[40];
  std::snprintf(text, sizeof text, "%.6f", t);
  return text;
}

}  // namespace

// Whether the first kIndexFrames frame lines of `lines` (the first of them `first`) have "t"
// k, k+1, k+2, …
bool countsFrames(LineReader& lines, std::string_view first) {
  double expected = -1;
  std::string_view line = first;
  for (int k = 0; k < kIndexFrames; ++k) {
    if (k > 0 && !nextLine(lines, line, nullptr)) return false;
    auto parsed = parseRecordLine(line, 0, true);
    auto* frame = std::get_if<RecordedFrame>(&parsed);
    if (!frame || frame->t != std::floor(frame->t) || (k > 0 && frame->t != expected)) return false;
    expected = frame->t + 1;
  }
  return true;
}

RecordKind recordKind(std::istream& in) {
  RecordKind kind = RecordKind::Timed;
  LineReader lines(in);
  if (std::string_view line; nextLine(lines, line, nullptr)) {
    if (line[line.find_first_not_of(" \t")] == '{') {  // not blank: there is one
      // a frame but for its time (read as a record's lines are, hostile ones too)
      if (std::holds_alternative<RecordedFrame>(parseRecordLine(line, 0, false)) &&
          !std::holds_alternative<RecordedFrame>(parseRecordLine(line, 0, true)))
        kind = RecordKind::UntimedJson;
      else if (countsFrames(lines, line))
        kind = RecordKind::IndexedJson;
    } else if (std::holds_alternative<CaptureLine>(parseCaptureLine(line))) {
      kind = RecordKind::CaptureText;
    }
  }
  in.clear();
  in.seekg(0);
  return kind;
}

Result<TimedCapture, std::string> timeCapture(std::istream& in, RecordKind kind,
                                              const CaptureTiming& timing) {
  TimedCapture out;
  std::vector<RecordedFrame> frames;
  std::map<std::string, int> numbers;  // a capture's car names, numbered as they appear
  LineReader lines(in);
  for (std::string_view line; nextLine(lines, line, &out.bad);) {
    RecordedFrame frame;
    if (kind == RecordKind::CaptureText) {
      auto parsed = parseCaptureLine(line);
      if (auto* why = std::get_if<std::string>(&parsed)) {
        out.bad.add({lines.number(), std::move(*why)});
        continue;
      }
      auto& c = std::get<CaptureLine>(parsed);
      auto [at, added] = numbers.emplace(c.car, static_cast<int>(numbers.size()) + 1);
      if (at->second > kMaxRecordedCar)
        return Unexpected("more than " + std::to_string(kMaxRecordedCar) +
                          " cars in the capture (the " + std::to_string(at->second) + "th is " +
                          printable(c.car, 40) + "): split it by car");
      frame.car = at->second;
      if (added) frame.name = printable(c.car, kMaxRecordedName - 3);  // room for its "…"
      frame.bytes = std::move(c.bytes);  // a capture holds what the cars sent
    } else {
      auto parsed = parseRecordLine(line, 0, false);
      if (auto* why = std::get_if<std::string>(&parsed)) {
        out.bad.add({lines.number(), std::move(*why)});
        continue;
      }
      frame = std::move(std::get<RecordedFrame>(parsed));
      if (frame.car == 0 || frame.link) continue;  // a race's or a link's line: no frame
    }
    frame.line = lines.number();
    if (frames.size() == kMaxCaptureFrames)
      return Unexpected(
          "a capture without times is read whole to time its frames, and this one "
          "has more than " +
          std::to_string(kMaxCaptureFrames) +
          " frames: split it, or give it times (\"t\" in seconds on every line)");
    frames.push_back(std::move(frame));
  }
  if (in.bad()) return Unexpected(std::string("the capture could not be read to its end"));

  std::vector<double> times(frames.size(), 0);
  if (timing.interval) {
    for (std::size_t i = 0; i < frames.size(); ++i)
      times[i] = *timing.interval * static_cast<double>(i);
    out.how = "times at the stated interval, " + seconds(*timing.interval) + " s a frame";
  } else {
    std::map<int, CarClock> clocks;
    for (std::size_t i = 0; i < frames.size(); ++i)
      clocks.try_emplace(frames[i].car, times).first->second.add(i, frames[i].bytes, frames[i].tx);
    for (auto& [car, clock] : clocks) {
      clock.finish();
      out.inferred += clock.inferred();
    }
    out.how = "times inferred from the cars' speeds and wheel distances for " +
              std::to_string(out.inferred) + " of " + std::to_string(frames.size()) +
              " frames; the others " + std::to_string(static_cast<int>(kCaptureGap * 1000)) +
              " ms apart, or as far apart as those of the piece before (--interval S states one)";
  }

  for (double& t : times) t = std::min(t, kMaxRecordedTime);  // as a record may hold
  // In the order of their times; a car's own frames keep theirs.
  std::vector<std::size_t> order(frames.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return times[a] < times[b]; });
  std::string text;
  for (std::size_t i : order) {
    const RecordedFrame& f = frames[i];
    text += "{\"t\":" + seconds(times[i]) + ",\"car\":" + std::to_string(f.car) + ",\"dir\":\"" +
            (f.tx ? "tx" : "rx") + "\",\"hex\":\"" + toHex(f.bytes) + "\"";
    // (names and layouts are checked text already; `replace` keeps a slip from throwing)
    auto json = [](const std::string& s) {
      return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    };
    if (!f.name.empty()) text += ",\"carName\":" + json(f.name);
    if (!f.layout.empty()) text += ",\"layout\":" + json(f.layout);
    text += "}\n";
  }
  out.record = std::move(text);
  out.frames = frames.size();
  return out;
}

}  // namespace pitwall
