#pragma once
// `--record FILE`: every frame in and out of every car as one JSON object per line:
//   {"t":1.234567,"car":1,"dir":"tx","hex":"06 24 58 02 e8 03 00","msg":{"name":"set-speed",…}}
// Times are engine-clock seconds with microsecond resolution, so a virtual-time run with the
// same seed writes the same bytes.
//
// The record is never lost (docs/safety.md): lines reach the file at least every 50 ms of real
// time while frames come (and the session flushes every 50 ms in real time when none come), at
// every way out of a run, and from a crash signal (SIGSEGV, SIGABRT, …) through write(2) of
// whole lines only. A killed run loses at most its last 100 ms.
#include <chrono>
#include <span>
#include <string>

#include "engine/protocol/anki/messages.hpp"

namespace pitwall {

class Recorder {
 public:
  // Throws std::runtime_error naming the file when it cannot be opened.
  explicit Recorder(const std::string& path);
  // A record of a run that may still be refused at start (docs/safety.md): the file is only
  // checked now (it could be written), not opened, so a refused start leaves an old record as it
  // was; lines are kept in memory until open() truncates the file and writes them. Throws as
  // above when the file could not be written.
  struct Later {};
  Recorder(const std::string& path, Later);
  // The file is opened (truncated) and what was kept reaches it. Throws as the constructor.
  void open();
  bool opened() const { return fd_ >= 0; }
  ~Recorder();  // flushes
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // `extra`: more members for this line, each `,"key":value` (a car's first line carries its
  // "carName", the record's first line the "layout": docs/cli.md "Record format").
  void write(double t, int car, bool tx, std::span<const std::uint8_t> frame,
             const anki::Message& message, std::string_view extra = {});
  // A race line, {"t":…,"race":RACE} (docs/cli.md "Record format"): `race` is JSON text, an
  // object or null. One over kMaxLineBytes of a record is not written (a replay could not read
  // it); false then.
  bool writeRace(double t, std::string_view race);
  // A link line, {"t":…,"car":N,"link":LINK} (docs/cli.md "Record format"): `link` is a JSON
  // object's text, at most a few hundred bytes.
  void writeLink(double t, int car, std::string_view link);
  // Everything written so far reaches the file.
  void flush();
  std::size_t lines() const { return lines_; }

 private:
  static constexpr std::size_t kCapacity = std::size_t{1} << 18;
  int fd_ = -1;
  std::string path_;
  char* buffer_;          // kCapacity bytes, never reallocated (a crash handler reads it)
  std::size_t used_ = 0;  // whole lines only
  std::size_t lines_ = 0;
  std::chrono::steady_clock::time_point lastFlush_;
  bool failed_ = false;
  std::string early_;  // lines kept before open()
  void append(const std::string& line);
};

}  // namespace pitwall
