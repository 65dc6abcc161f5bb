#pragma once
// `--record FILE`: every frame in and out of every car as one JSON object per line:
//   {"t":1.234567,"car":1,"dir":"tx","hex":"06 24 58 02 e8 03 00","msg":{"name":"set-speed",…}}
// Times are engine-clock seconds with microsecond resolution, so a virtual-time run with the
// same seed writes the same bytes.
#include <fstream>
#include <span>
#include <string>

#include "engine/protocol/anki/messages.hpp"

namespace pitwall {

class Recorder {
 public:
  // Throws std::runtime_error naming the file when it cannot be opened.
  explicit Recorder(const std::string& path);
  void write(double t, int car, bool tx, std::span<const std::uint8_t> frame,
             const anki::Message& message);
  std::size_t lines() const { return lines_; }

 private:
  std::ofstream out_;
  std::size_t lines_ = 0;
};

}  // namespace pitwall
