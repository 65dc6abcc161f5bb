// Reading a --record file back (engine/record/record_reader.hpp), the input of `pitwall replay`:
// any bytes are a file. Never a crash or an exception; every line is a frame, a bad line with its
// number and a short reason, valid UTF-8 without control characters, or blank; frames keep the
// reader's promises (car 1..64, t within range and never going back by more than the slack, a
// non-empty frame); the parse of one line is the same alone as within the file. Read as a capture
// without times (engine/record/capture.hpp), it is timed or refused with a short sentence, and
// what timing writes is a record that reads back whole: the same frames, times in order.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <regex>
#include <sstream>
#include <string>

#include "engine/record/capture.hpp"
#include "engine/record/record_reader.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace pitwall;

namespace {
// The reason a frame far ahead of the next is left out with (nothing of a line's text in it)
const std::regex kOdd(
    R"("t" [0-9.e+\-]+ lies ahead of the frames around it \(the next is at [0-9.e+\-]+\))");

// Valid UTF-8 without control characters: what a terminal shows as it is.
bool printable(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) return false;
    std::size_t n = c < 0x80           ? 1
                    : (c >> 5) == 0x6  ? 2
                    : (c >> 4) == 0xe  ? 3
                    : (c >> 3) == 0x1e ? 4
                                       : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (std::size_t k = 1; k < n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
    i += n;
  }
  return true;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::istringstream in(text);
  Record record = readRecord(in);

  std::size_t lines = 0;
  for (char c : text) lines += c == '\n';
  if (!text.empty() && text.back() != '\n') ++lines;
  FUZZ_CHECK(record.frames.size() + record.bad.size() <= lines, text);

  double last = -1;
  std::size_t lastLine = 0;
  for (const auto& f : record.frames) {
    FUZZ_CHECK(f.car >= 1 && f.car <= kMaxRecordedCar, text);
    FUZZ_CHECK(std::isfinite(f.t) && f.t >= 0 && f.t <= kMaxRecordedTime, text);
    FUZZ_CHECK(last < 0 || f.t >= last - kBackwardsSlack - 1e-9, text);
    FUZZ_CHECK(!f.bytes.empty(), text);
    FUZZ_CHECK(f.line > lastLine && f.line <= lines, text);
    last = std::max(last, f.t);
    lastLine = f.line;
  }
  lastLine = 0;
  for (const auto& b : record.bad) {
    FUZZ_CHECK(b.line > lastLine && b.line <= lines, text);
    FUZZ_CHECK(!b.why.empty() && b.why.size() < 400, text);
    FUZZ_CHECK(printable(b.why), b.why);
    lastLine = b.line;
  }
  // the first line alone reads the same as in the file, but for a frame the file's later lines
  // show to lie far ahead of them (then it is named so)
  std::string first = text.substr(0, text.find('\n'));
  if (!first.empty() && first.back() == '\r') first.pop_back();
  if (first.size() <= kMaxLineBytes && first.find_first_not_of(" \t") != std::string::npos) {
    auto alone = parseRecordLine(first, 0);  // the reader starts at t = 0
    const bool frame = !record.frames.empty() && record.frames.front().line == 1;
    const bool odd = !record.bad.empty() && record.bad.front().line == 1 &&
                     std::regex_match(record.bad.front().why, kOdd);
    FUZZ_CHECK(std::holds_alternative<RecordedFrame>(alone) == (frame || odd), first);
  }

  std::istringstream again(text);
  const RecordKind kind = recordKind(again);
  if (kind != RecordKind::Timed) {
    for (std::optional<double> interval : {std::optional<double>{}, std::optional<double>{0.05}}) {
      again.clear();
      again.seekg(0);
      auto timed = timeCapture(again, kind, CaptureTiming{interval});
      if (!timed) {
        FUZZ_CHECK(!timed.error().empty() && timed.error().size() < 400, text);
        FUZZ_CHECK(printable(timed.error()), timed.error());
        continue;
      }
      std::istringstream written(timed->record);
      Record back = readRecord(written);
      FUZZ_CHECK(back.bad.empty(), timed->record);
      FUZZ_CHECK(back.frames.size() == timed->frames, timed->record);
      FUZZ_CHECK(timed->frames + timed->bad.count <= lines, text);
      for (std::size_t i = 1; i < back.frames.size(); ++i)
        FUZZ_CHECK(back.frames[i].t >= back.frames[i - 1].t, timed->record);
      for (const auto& b : timed->bad.first) FUZZ_CHECK(printable(b.why), b.why);
    }
  }
  return 0;
}
