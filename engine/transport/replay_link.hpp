#pragma once
// The link of a replayed car (pitwall replay, docs/view.md "Replays"): its frames come from a
// record, delivered by the player at their recorded times; what the controller side sends goes
// nowhere. A command (a script's, the stop at the end of the run) is logged at info as not sent,
// so a post-mortem run shows what the script would have done; the greeting every connected car
// gets (SDK mode, version and battery asked) at debug.
#include <string>

#include "engine/transport/link.hpp"

namespace pitwall {

class ReplayLink : public Link {
 public:
  // `label` names the car in the log ("car 1").
  explicit ReplayLink(std::string label);

  void connect();  // the car is there (reported at once)
  // One recorded frame from the car.
  void deliver(std::span<const std::uint8_t> frame) { deliverFrame(frame); }

  bool send(std::span<const std::uint8_t> frame) override;  // logs it; true while connected
  bool connected() const override { return connected_; }
  void disconnect() override;
  std::string address() const override { return "replay:" + label_; }

 private:
  std::string label_;
  bool connected_ = false;
  bool handshake_ = false;  // while connect() reports the car: the controller's greeting
};

}  // namespace pitwall
