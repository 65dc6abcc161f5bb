#pragma once
// The simulator link: the mock transport. It carries real frames between a controller-side
// vehicle model and a simulated car, with a fixed one-way latency on the engine loop and, in real
// time, a BLE connection interval: a frame waits for the link's next connection event, as it
// does on a real car's connection (docs/simulator.md "Timing"). Order is kept either way.
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
  // BlueZ asks a car for a 30–50 ms interval (its default LE connection parameters); real-time
  // links take the shortest of it. Virtual time keeps frames on the fixed latency alone.
  static constexpr Duration kRealTimeInterval = std::chrono::milliseconds(30);
  static constexpr Duration kRetry = std::chrono::milliseconds(500);

  SimLink(Loop& loop, sim::SimCar& car, Duration latency = kDefaultLatency);
  // Connection events every `interval` (zero: none, the fixed latency alone), at a phase of the
  // link's own taken from the car's identifier, as two cars' connections do not beat together.
  void setConnectionInterval(Duration interval);
  Duration connectionInterval() const { return interval_; }
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
  Duration interval_{};
  Duration phase_{};
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
  // The car dropped the connection (it reset, it was told to): connect again once it can be
  // connected, looking every kRetry, as a BLE link reconnects a car that dropped.
  void retryLater();
  Loop::TimerId retryTimer_ = 0;
  std::weak_ptr<const void> carLife_;  // the car's world may go first
  void reportState(bool up, std::string reason);
  std::deque<InFlight> toCar_, toController_;
  Loop::TimerId toCarTimer_ = 0, toControllerTimer_ = 0;
};

}  // namespace pitwall
