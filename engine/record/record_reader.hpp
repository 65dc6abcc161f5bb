#pragma once
// Reading a `--record` file back (docs/cli.md "Record format", engine/record/recorder.hpp): one
// JSON object per line, {"t":…,"car":N,"dir":"rx"|"tx","hex":"…","msg":{…}}. Only t, car, dir
// and hex are read: the frame is decoded again by whoever replays it, so "msg" is never trusted.
// A line {"t":…,"race":{…}} is the race as the run's race library reported it, for the view.
//
// The file may be cut short (a killed run), edited or hostile: a line that is not a frame is
// set aside with its number and why, and the rest is read. Nothing in a line can crash the
// reader: a line is at most kMaxLineBytes (longer ones are skipped unread), JSON nesting is
// checked before a document is built, numbers are range-checked before they are narrowed.
#include <cstdint>
#include <istream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pitwall {

struct RecordedFrame {
  double t = 0;  // engine seconds of the recorded run
  int car = 0;   // the recording's car number, 1..kMaxRecordedCar; 0: a race line (below)
  bool tx = false;
  std::vector<std::uint8_t> bytes;
  std::size_t line = 0;  // 1-based line number in the file
  // A car's first line carries its "carName", the record's first line the simulator's "layout"
  // (empty when the line has none, or one that is no string of a sensible length).
  std::string name;
  std::string layout;
  // A line {"t":…,"race":{…}} (car 0, no bytes): the race as the race library reported it at t
  // (pitwall.view.race; "null" when it ended), as JSON text for a replay's view.
  std::string race;
  // A line {"t":…,"car":N,"link":{"up":…,"reason":…,"writeFailures":…,"stalls":…,"rssi":…}}
  // (no bytes): the car's link went up or down (docs/cli.md "Record format").
  struct Link {
    bool up = false;
    std::string reason;  // why it went down; printable, at most kMaxRecordedName * 4 bytes
    int writeFailures = 0;
    int stalls = 0;
    std::optional<int> rssi;
  };
  std::optional<Link> link;
};

struct BadLine {
  std::size_t line = 0;  // 1-based
  std::string why;       // "not JSON: …", "\"car\" must be an integer 1..64, not 0", …
};

inline constexpr std::size_t kBadLinesKept = 20;

// The bad lines of a record: the first `keep` (in line order) with their numbers and why, and
// how many in all. A file of nothing but bad lines costs a count, not a copy of each.
struct BadLines {
  std::vector<BadLine> first;
  std::size_t count = 0;
  std::size_t keep = kBadLinesKept;
  void add(BadLine bad);
};

// A whole record in memory: for tests and small files. `pitwall replay` streams (RecordStream).
struct Record {
  std::vector<RecordedFrame> frames;  // in file order; times never go backwards by more than
                                      // kBackwardsSlack
  std::vector<RecordedFrame> races;   // the race lines (car 0), in file order
  std::vector<RecordedFrame> links;   // the cars' link lines (RecordedFrame::link), in file order
  std::vector<BadLine> bad;           // every one
  std::map<int, std::string> names;   // the cars' names, where the record keeps them
  std::string layout;                 // the track's layout text; empty: the record keeps none
};

// What a replay needs to know before it plays: one pass over the file, nothing of it kept but
// these (memory does not grow with the record's length).
struct RecordSummary {
  std::size_t frames = 0;
  std::size_t raceLines = 0;  // lines of the race (car 0), not counted in frames
  std::map<int, int> drops;   // the link lines that say a car's link went down, by car
  double duration = 0;        // the last line's time (the latest of all)
  BadLines bad;
  std::map<int, std::string> names;        // as in Record
  std::map<int, std::uint64_t> framesOut;  // every recorded car's number: its tx frames
  std::string layout;                      // as in Record
};

inline constexpr std::size_t kMaxLineBytes = 64 * 1024;
inline constexpr int kMaxRecordedCar = 64;           // as --cars
inline constexpr double kMaxRecordedTime = 1e7;      // seconds (116 days): any real run is shorter
inline constexpr double kBackwardsSlack = 0.001;     // seconds a line's t may lie before the last
inline constexpr int kMaxJsonDepth = 16;             // a frame's line nests 2 deep ("msg")
inline constexpr std::size_t kMaxRecordedName = 64;  // bytes of a car's name
inline constexpr std::size_t kMaxRecordedLayout = 8192;  // bytes of a layout's text

// One line (without its newline) against the time of the last good frame; the frame, or why not.
// With `timed` false a line without "t" is a frame at time 0 (a capture without times,
// engine/record/capture.hpp).
std::variant<RecordedFrame, std::string> parseRecordLine(std::string_view line, double lastTime,
                                                         bool timed = true);

// The lines of a stream, each at most kMaxLineBytes: a longer one is skipped unread (its length
// told), so that no line costs more than the buffer. One buffer, reused.
class LineReader {
 public:
  explicit LineReader(std::istream& in);
  enum class Got { Line, TooLong, End };
  // The next line without its newline (nor a '\r' before it), valid until the next call; or
  // TooLong with its length in `tooLong`; or End (the end of the stream, or a read error).
  Got next(std::string_view& line, std::size_t& tooLong);
  std::size_t number() const { return number_; }  // the last line's, from 1
  bool atEnd() const { return end_; }
  void restart();  // after the stream was put back to its start

 private:
  std::istream& in_;
  std::string buffer_;
  std::size_t number_ = 0;
  bool end_ = false;
};

// "a line of N bytes, longer than 65536: not a frame of a record"
std::string lineTooLong(std::size_t length);

// The frames of a record one at a time, as they are read: the same frames and bad lines as
// readRecord gives, in the same order, holding one line and one frame (a frame far ahead of the
// frames around it is told only by the frame after it: each frame is handed on once the next is
// read).
class RecordStream {
 public:
  explicit RecordStream(std::istream& in, std::size_t keepBad = kBadLinesKept);
  // The next frame that is whole, or nothing at the end of the file (or a read error: in.bad()).
  std::optional<RecordedFrame> next() { return next(std::numeric_limits<std::size_t>::max()); }
  // The same, reading at most `lines` lines: nothing, with done() false, when they ran out
  // before a frame came (a long run of bad lines) — call again, after the loop has turned.
  std::optional<RecordedFrame> next(std::size_t lines);
  // The end of the file reached and every frame handed on.
  bool done() const { return end_ && !pending_; }
  // Back to the first line (the stream must be a file's); the bad lines are counted again.
  bool rewind();
  const BadLines& bad() const { return bad_; }

 private:
  // A line that parses, its time not yet checked; nothing at the end or when `lines` ran out.
  std::optional<RecordedFrame> parseNext(std::size_t& lines);

  std::istream& in_;
  LineReader lines_;
  bool end_ = false;
  double lastTime_ = 0;
  double before_ = 0;  // the time of the frame handed on before pending_ (0: none)
  std::optional<RecordedFrame> pending_;
  BadLines bad_;
};

// Every line of `in`, every frame and bad line kept. Blank lines are skipped silently.
Record readRecord(std::istream& in);
// One pass over `in` for a replay: counts, cars, names, duration and the first bad lines.
RecordSummary scanRecord(std::istream& in);

}  // namespace pitwall
