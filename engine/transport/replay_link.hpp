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

  // A recorded link line: the link goes down (with its reason) or up again, as it did in the
  // run, and health() tells what the run's link told then.
  void recorded(bool up, const std::string& reason, const LinkHealth& health);
  // Back to the record's start (a seek back): connected, as every car is there, with no news of
  // its health; nothing is reported (the car rewinds itself).
  void rewind() {
    connected_ = true;
    health_ = {};
  }

  bool send(std::span<const std::uint8_t> frame) override;  // logs it; true while connected
  LinkHealth health() const override { return health_; }
  bool connected() const override { return connected_; }
  void disconnect() override;
  std::string address() const override { return "replay:" + label_; }

 private:
  std::string label_;
  bool connected_ = false;
  bool handshake_ = false;  // while connect() reports the car: the controller's greeting
  LinkHealth health_;
};

}  // namespace pitwall
