#pragma once
// Fault injection for any link, the same way for every device (after Boost.Beast's test stream
// and its fail_count: a test can loop over every failure point). A FaultyLink wraps a link (the
// simulator link of an Anki car, the socket or GATT link of a robot) and passes everything
// through, except the faults it is told to inject:
//   failSend = N        the Nth send() (1-based) fails: false, nothing sent, and refusal() says
//                       "injected fault: send N failed" — the model's refusal sentence names it
//   dropAfterFrames = N after the Nth frame from the device is delivered, the connection drops:
//                       the wrapped link is asked to reconnect(), so the drop (reported with
//                       the injected reason) and what follows go the way a real loss would
//   refuseConnects = N  the first N connections that come up are dropped at once, before the
//                       model hears of them: to the model, attempts that failed
// Every injected reason starts with "injected fault: ". No timers, no I/O of its own.
#include <cstddef>
#include <memory>
#include <string>

#include "engine/transport/link.hpp"

namespace pitwall {

struct Faults {
  std::size_t failSend = 0;         // 0: none
  std::size_t dropAfterFrames = 0;  // 0: none
  std::size_t refuseConnects = 0;   // 0: none
};

class FaultyLink : public Link {
 public:
  // Wraps `inner`, owned (a robot's model owns its link) or not (an AnkiCar's link is the
  // caller's). Takes over the inner link's handlers.
  FaultyLink(std::unique_ptr<Link> inner, Faults faults);
  FaultyLink(Link& inner, Faults faults);
  ~FaultyLink() override;

  bool send(std::span<const std::uint8_t> frame) override;
  bool connected() const override { return inner_.connected(); }
  void disconnect() override { inner_.disconnect(); }
  void reconnect(const std::string& reason) override { inner_.reconnect(reason); }
  std::string address() const override { return inner_.address(); }
  std::string refusal() const override;
  std::optional<double> retryIn() const override { return inner_.retryIn(); }
  std::optional<double> knownOffset() const override { return inner_.knownOffset(); }

  Faults& faults() { return faults_; }
  std::size_t sends() const { return sends_; }
  std::size_t frames() const { return frames_; }
  Link& inner() { return inner_; }

 private:
  void hook();
  void drop(const std::string& reason);  // asks the wrapped link to reconnect

  std::unique_ptr<Link> owned_;
  Link& inner_;
  Faults faults_;
  std::size_t sends_ = 0, frames_ = 0, connects_ = 0;
  std::string injected_;  // the refusal of the last send, when it was injected
  std::string dropping_;  // the reason of a drop asked for and not reported yet
};

}  // namespace pitwall
