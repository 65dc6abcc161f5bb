#include "engine/vehicles/recorder.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "engine/protocol/anki/message_json.hpp"

namespace pitwall {

std::string toHex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  out.reserve(bytes.size() * 3);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) out += ' ';
    out += kDigits[bytes[i] >> 4];
    out += kDigits[bytes[i] & 0x0f];
  }
  return out;
}

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
