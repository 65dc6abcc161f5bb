#pragma once
// Captures without times (docs/cli.md "Captures without times"): frames a controller logged from
// real cars with no clock — tests/realdata's `INDEX CAR HEX…` lines, or record lines without
// "t" — given times so that a replay can play them. Times are inferred from what the cars
// report: a transition update (0x29) carries the wheel distances of the piece just left, and the
// position updates (0x27) on it the car's speed, so each piece took distance ÷ speed; the frames
// between two transitions are spread evenly over it. Or every frame comes a stated interval
// after the one before.
//
// A capture is read whole to do that (the frames of a piece are timed only once its end is
// seen), so it is bounded: kMaxCaptureFrames.
#include <cstddef>
#include <istream>
#include <optional>
#include <string>

#include "engine/core/result.hpp"
#include "engine/record/record_reader.hpp"

namespace pitwall {

enum class RecordKind {
  Timed,        // a --record file: JSON lines with "t"
  UntimedJson,  // JSON lines of frames, none with "t"
  IndexedJson,  // JSON lines of frames whose "t" counts them (0, 1, 2, …): an index, not seconds
  CaptureText,  // `INDEX CAR HEX…` lines: the index is an order, not a time
};

// What the first lines that are not blank look like; `in` is read from its start and put back
// there. A record whose first kIndexFrames frames have "t" k, k+1, k+2, … counts its frames
// (no run sends a frame a second for that long). A file that is none of these is taken for a
// record (and its bad lines said so).
inline constexpr int kIndexFrames = 3;
RecordKind recordKind(std::istream& in);

inline constexpr std::size_t kMaxCaptureFrames = 500000;
// A frame's time when nothing better is known: before a car's first transition, on a piece whose
// speed no frame says, or after its last transition without a piece to go by.
inline constexpr double kCaptureGap = 0.01;  // seconds

struct CaptureTiming {
  std::optional<double> interval;  // seconds between frames, stated: nothing is inferred
};

struct TimedCapture {
  std::string record;        // JSON lines as --record writes them (without "msg")
  std::size_t frames = 0;    // frames in the record
  std::size_t inferred = 0;  // of them, timed by a piece's distance and speed
  BadLines bad;              // lines that are no frame, as a record's
  std::string how;           // one sentence: how the times were found
};

// The capture in `in` (RecordKind UntimedJson, IndexedJson or CaptureText) with times; an
// index for a time is left aside. An error is a sentence:
// too many frames, or too many cars (a capture names them; the first kMaxRecordedCar are
// numbered in the order they appear).
Result<TimedCapture, std::string> timeCapture(std::istream& in, RecordKind kind,
                                              const CaptureTiming& timing);

}  // namespace pitwall
