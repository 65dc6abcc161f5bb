#pragma once
// A Link for tests: records what the controller sends and lets the test play the car's part.
#include <string>
#include <vector>

#include "engine/protocol/anki/codec.hpp"
#include "engine/transport/link.hpp"

namespace pitwall::testing {

class CaptureLink : public Link {
 public:
  bool send(std::span<const std::uint8_t> frame) override {
    if (!up) return false;
    sent.emplace_back(frame.begin(), frame.end());
    return true;
  }
  bool connected() const override { return up; }
  void disconnect() override { setConnected(false, "asked to disconnect"); }
  std::string address() const override { return "capture"; }

  void setConnected(bool value, const std::string& reason = "test") {
    up = value;
    deliverState(value, reason);
  }
  void carSends(const anki::Message& m) {
    anki::Frame f = anki::encode(m);
    deliverFrame(f.span());
  }
  void carSendsBytes(std::vector<std::uint8_t> bytes) { deliverFrame(bytes); }
  anki::Message lastSent() const { return *anki::decode(sent.back()); }

  bool up = false;
  std::vector<std::vector<std::uint8_t>> sent;
};

}  // namespace pitwall::testing
