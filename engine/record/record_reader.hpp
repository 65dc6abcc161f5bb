#pragma once
// Reading a `--record` file back (docs/cli.md "Record format", engine/record/recorder.hpp): one
// JSON object per line, {"t":…,"car":N,"dir":"rx"|"tx","hex":"…","msg":{…}}. Only t, car, dir
// and hex are read: the frame is decoded again by whoever replays it, so "msg" is never trusted.
//
// The file may be cut short (a killed run), edited or hostile: a line that is not a frame is
// set aside with its number and why, and the rest is read. Nothing in a line can crash the
// reader: a line is at most kMaxLineBytes (longer ones are skipped unread), JSON nesting is
// checked before a document is built, numbers are range-checked before they are narrowed.
#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pitwall {

struct RecordedFrame {
  double t = 0;  // engine seconds of the recorded run
  int car = 0;   // the recording's car number, 1..kMaxRecordedCar
  bool tx = false;
  std::vector<std::uint8_t> bytes;
  std::size_t line = 0;  // 1-based line number in the file
  // A car's first line carries its "carName", the record's first line the simulator's "layout"
  // (empty when the line has none, or one that is no string of a sensible length).
  std::string name;
  std::string layout;
};

struct BadLine {
  std::size_t line = 0;  // 1-based
  std::string why;       // "not JSON: …", "\"car\" must be an integer 1..64, not 0", …
};

struct Record {
  std::vector<RecordedFrame> frames;  // in file order; times never go backwards by more than
                                      // kBackwardsSlack
  std::vector<BadLine> bad;
  std::map<int, std::string> names;  // the cars' names, where the record keeps them
  std::string layout;                // the track's layout text; empty: the record keeps none
};

inline constexpr std::size_t kMaxLineBytes = 64 * 1024;
inline constexpr int kMaxRecordedCar = 64;           // as --cars
inline constexpr double kMaxRecordedTime = 1e7;      // seconds (116 days): any real run is shorter
inline constexpr double kBackwardsSlack = 0.001;     // seconds a line's t may lie before the last
inline constexpr int kMaxJsonDepth = 16;             // a frame's line nests 2 deep ("msg")
inline constexpr std::size_t kMaxRecordedName = 64;  // bytes of a car's name
inline constexpr std::size_t kMaxRecordedLayout = 8192;  // bytes of a layout's text

// One line (without its newline) against the time of the last good frame; the frame, or why not.
std::variant<RecordedFrame, std::string> parseRecordLine(std::string_view line, double lastTime);
// Every line of `in`. Blank lines are skipped silently.
Record readRecord(std::istream& in);

}  // namespace pitwall
