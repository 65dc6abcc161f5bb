#pragma once
// The simulator link: the mock transport. It carries real frames between a controller-side
// vehicle model and a simulated car, with a fixed one-way latency on the engine loop, the way a
// BLE connection interval delays them.
#include <deque>
#include <memory>

#include "engine/core/loop.hpp"
#include "engine/protocol/anki/messages.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/link.hpp"

namespace pitwall {

class SimLink : public Link {
 public:
  static constexpr Duration kDefaultLatency = std::chrono::milliseconds(10);

  SimLink(Loop& loop, sim::SimCar& car, Duration latency = kDefaultLatency);
  ~SimLink() override;

  // Connects to the simulated car; the state handler reports it on the loop.
  void connect();
  bool send(std::span<const std::uint8_t> frame) override;
  bool connected() const override { return connected_; }
  void disconnect() override;
  std::string address() const override;
  std::optional<double> knownOffset() const override { return car_.believedOffset(); }
  sim::SimCar& car() { return car_; }

 private:
  Loop& loop_;
  sim::SimCar& car_;
  Duration latency_;
  bool connected_ = false;
  std::shared_ptr<bool> alive_;  // guards callbacks queued on the loop after destruction

  // Frames in flight, each way, in order; one timer per direction is armed for the oldest.
  struct InFlight {
    TimePoint due;
    anki::Frame frame;
  };
  void enqueue(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar,
               std::span<const std::uint8_t> frame);
  void arm(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar);
  void deliver(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar);
  void deliverToCar();
  void deliverToController();
  void lost(const std::string& reason);  // the connection is gone: clear, report
  void reportState(bool up, std::string reason);
  std::deque<InFlight> toCar_, toController_;
  Loop::TimerId toCarTimer_ = 0, toControllerTimer_ = 0;
};

}  // namespace pitwall
