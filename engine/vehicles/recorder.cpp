#include "engine/vehicles/recorder.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "engine/core/hex.hpp"
#include "engine/protocol/anki/message_json.hpp"

namespace pitwall {

Recorder::Recorder(const std::string& path) : out_(path, std::ios::out | std::ios::trunc) {
  if (!out_)
    throw std::runtime_error("cannot open record file " + path + ": " + std::strerror(errno));
}

void Recorder::write(double t, int car, bool tx, std::span<const std::uint8_t> frame,
                     const anki::Message& message) {
  char stamp[32];
  std::snprintf(stamp, sizeof stamp, "%.6f", t);
  out_ << "{\"t\":" << stamp << ",\"car\":" << car << ",\"dir\":\"" << (tx ? "tx" : "rx")
       << "\",\"hex\":\"" << toHex(frame) << "\",\"msg\":" << anki::toJson(message).dump() << "}\n";
  ++lines_;
}

}  // namespace pitwall
