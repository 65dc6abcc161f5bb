// Fault injection on a link (faulty_link.hpp).
#include "engine/transport/faulty_link.hpp"

namespace pitwall {

FaultyLink::FaultyLink(std::unique_ptr<Link> inner, Faults faults)
    : owned_(std::move(inner)), inner_(*owned_), faults_(faults) {
  hook();
}

FaultyLink::FaultyLink(Link& inner, Faults faults) : inner_(inner), faults_(faults) {
  hook();
}

FaultyLink::~FaultyLink() {
  inner_.onFrame(nullptr);
  inner_.onState(nullptr);
}

void FaultyLink::hook() {
  inner_.onFrame([this](std::span<const std::uint8_t> frame) {
    ++frames_;
    deliverFrame(frame);
    if (faults_.dropAfterFrames != 0 && frames_ == faults_.dropAfterFrames && inner_.connected())
      drop("injected fault: dropped after " + std::to_string(frames_) + " frames");
  });
  inner_.onState([this](bool up, const std::string& reason) {
    if (up && connects_ < faults_.refuseConnects) {
      ++connects_;
      // The model never hears of this connection, only of its end.
      return drop("injected fault: connection " + std::to_string(connects_) + " refused");
    }
    if (!up && !dropping_.empty()) {
      // The drop we caused, whatever the wrapped link calls it.
      std::string why = std::move(dropping_);
      dropping_.clear();
      return deliverState(false, why);
    }
    deliverState(up, reason);
  });
}

void FaultyLink::drop(const std::string& reason) {
  dropping_ = reason;
  inner_.reconnect(reason);
}

bool FaultyLink::send(std::span<const std::uint8_t> frame) {
  ++sends_;
  if (faults_.failSend != 0 && sends_ == faults_.failSend) {
    injected_ = "injected fault: send " + std::to_string(sends_) + " failed";
    return false;
  }
  injected_.clear();
  return inner_.send(frame);
}

std::string FaultyLink::refusal() const {
  return injected_.empty() ? inner_.refusal() : injected_;
}

}  // namespace pitwall
