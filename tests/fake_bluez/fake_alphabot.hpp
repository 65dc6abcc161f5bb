#pragma once
// The robot behind a fake Alphabot device (tests/fake_bluez): a small model that answers every
// BLE request through the real codec (engine/protocol/alphabot/ble_codec.hpp) — a room with
// walls and obstacles, a distance sensor, a compass, anchors, calibration, path finding — and
// records every write, for tests to check bytes and characteristics.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/protocol/alphabot/ble_codec.hpp"

namespace pitwall::testing {

class FakeAlphabot {
 public:
  // What the robot puts on a characteristic: notify (to subscribers) or only set (a read value).
  using Output = std::function<void(alphabot::ble::Characteristic, std::span<const std::uint8_t>,
                                    bool notify)>;

  FakeAlphabot(Loop& loop, int index);
  ~FakeAlphabot();

  // The GATT service the fake exports (the reference gives none: made up for the fake).
  static constexpr const char* kServiceUuid = "a1fab07e-0000-4000-8000-00a1fab07e00";
  // Timings: calibration takes a while; the path is "pending" shortly after a target is set.
  static constexpr Duration kCalibration = std::chrono::milliseconds(40);
  static constexpr Duration kPathDelay = std::chrono::milliseconds(30);

  void connect(Output out);
  void disconnect();
  // A client wrote `bytes` to `c`: decoded (errors are counted and ignored, as a robot would).
  void receive(alphabot::ble::Characteristic c, std::span<const std::uint8_t> bytes);
  std::vector<std::uint8_t> localName() const;

  // Ground truth.
  const std::vector<alphabot::ble::BleValue>& writes() const { return writes_; }
  int malformedWrites() const { return malformed_; }
  std::int8_t speed() const { return speed_; }
  std::int8_t steer() const { return steer_; }
  alphabot::Toggles toggles() const { return toggles_; }
  std::size_t obstacleCount() const { return obstacles_.size(); }
  std::optional<alphabot::Waypoint> target() const { return target_; }
  void heartbeat();  // notifies PINGCLIENT with the next counter value

 private:
  void handle(const alphabot::Request& r);
  void handle(const alphabot::ble::SensorQuery& q);
  void answer(const alphabot::Response& r);
  void put(const alphabot::ble::BleValue& v, bool notify);
  std::uint16_t distanceAt(int degree) const;
  alphabot::Path pathTo(alphabot::Waypoint target) const;

  Loop& loop_;
  int index_;
  Output out_;
  std::uint64_t generation_ = 0;  // one per connection: timers of older ones do nothing
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::vector<alphabot::ble::BleValue> writes_;
  int malformed_ = 0;
  std::int8_t speed_ = 0, steer_ = 0;
  alphabot::Toggles toggles_;
  std::int16_t x_ = 50, y_ = 50, heading_ = 0;  // cm, degrees
  std::vector<alphabot::ObstacleRegistered> obstacles_;
  std::uint8_t nextObstacle_ = 1;
  std::vector<alphabot::AnchorPosition> anchors_;
  std::optional<alphabot::Waypoint> target_;
  std::uint8_t beats_ = 0;
};

}  // namespace pitwall::testing
