#include "tests/fake_bluez/fake_alphabot.hpp"

#include <cmath>
#include <cstdio>

#include "engine/core/log.hpp"
#include "engine/core/overload.hpp"

namespace pitwall::testing {

namespace {

using namespace alphabot;
using ble::Characteristic;

// The room: 250 × 200 cm (MapSize has one byte per side), walls all round.
constexpr int kRoomLength = 250, kRoomWidth = 200;
constexpr int kSensorRange = 255;  // cm: the BLE distance byte

bool inside(const ObstacleRegistered& o, double x, double y) {
  return std::abs(x - o.x) <= o.width / 2.0 && std::abs(y - o.y) <= o.height / 2.0;
}

}  // namespace

FakeAlphabot::FakeAlphabot(Loop& loop, int index) : loop_(loop), index_(index) {}

FakeAlphabot::~FakeAlphabot() {
  *alive_ = false;
}

std::vector<std::uint8_t> FakeAlphabot::localName() const {
  std::string name = "Alphabot-" + std::to_string(index_ + 1);
  return {name.begin(), name.end()};
}

void FakeAlphabot::connect(Output out) {
  ++generation_;
  out_ = std::move(out);
  // What a client reads before anything happened.
  put(ble::encode(ble::TogglesReport{toggles_}), false);
  put(ble::encode(ble::Heartbeat{beats_}), false);
  put(*ble::encode(Response(Path{})), false);
}

void FakeAlphabot::disconnect() {
  ++generation_;
  out_ = nullptr;
  speed_ = steer_ = 0;  // a robot that loses its client stops
}

void FakeAlphabot::heartbeat() {
  put(ble::encode(ble::Heartbeat{++beats_}), true);
}

void FakeAlphabot::put(const ble::BleValue& v, bool notify) {
  if (out_) out_(v.characteristic, v.bytes, notify);
}

void FakeAlphabot::answer(const Response& r) {
  auto v = ble::encode(r);
  if (!v) {
    log::warn("fake-alphabot", v.error().message);
    return;
  }
  put(*v, true);
}

void FakeAlphabot::receive(Characteristic c, std::span<const std::uint8_t> bytes) {
  writes_.push_back(ble::BleValue{c, {bytes.begin(), bytes.end()}});
  auto message = ble::decodeRequest(c, bytes);
  if (!message) {
    ++malformed_;
    log::warn("fake-alphabot", "ignored: " + message.error().message);
    return;
  }
  std::visit([this](const auto& m) { handle(m); }, *message);
}

void FakeAlphabot::handle(const ble::SensorQuery& q) {
  switch (q.kind) {
    case ble::SensorKind::Compass:
      return answer(Compass{heading_});
    case ble::SensorKind::MapSize:
      return answer(MapSize{kRoomLength, kRoomWidth});
    case ble::SensorKind::Positioning:
      return answer(Position{x_, y_});
    default:
      return;
  }
}

void FakeAlphabot::handle(const Request& request) {
  std::visit(Overload{
                 [this](const Drive& m) {
                   speed_ = m.speed;
                   steer_ = m.steer;
                 },
                 [this](const MeasureDistance& m) {
                   answer(Distance{m.degree, distanceAt(m.degree)});
                 },
                 [this](const CalibrateSteering&) {
                   auto generation = generation_;
                   std::weak_ptr<bool> alive = alive_;
                   loop_.after(kCalibration, [this, alive, generation] {
                     if (!alive.expired() && generation == generation_)
                       answer(CalibrationFinished{});
                   });
                 },
                 [this](const CalibrateCompass&) {
                   auto generation = generation_;
                   std::weak_ptr<bool> alive = alive_;
                   loop_.after(kCalibration, [this, alive, generation] {
                     if (!alive.expired() && generation == generation_) {
                       heading_ = 0;
                       answer(CalibrationFinished{});
                     }
                   });
                 },
                 [this](const SetToggles& m) {
                   toggles_ = m.toggles;
                   put(ble::encode(ble::TogglesReport{toggles_}), true);
                 },
                 [](const Ping&) {},  // never written: over BLE a ping is a read
                 [this](const SetAnchor& m) {
                   std::erase_if(anchors_, [&](const AnchorPosition& a) { return a.id == m.id; });
                   anchors_.push_back(AnchorPosition{m.id, m.x, m.y});
                   answer(AnchorPosition{m.id, m.x, m.y});
                 },
                 [this](const NavigateTo& m) {
                   target_ = Waypoint{m.x, m.y};
                   // Pending at first, the path a little later: a client polls.
                   put(ble::encode(ble::PathPending{}), false);
                   auto generation = generation_;
                   std::weak_ptr<bool> alive = alive_;
                   loop_.after(kPathDelay, [this, alive, generation] {
                     if (alive.expired() || generation != generation_ || !target_) return;
                     auto v = ble::encode(Response(pathTo(*target_)));
                     if (v) put(*v, false);
                   });
                 },
                 [this](const AddObstacle& m) {
                   if (nextObstacle_ == ble::kRemoveByPosition) nextObstacle_ = 1;
                   ObstacleRegistered o{nextObstacle_++, m.x, m.y, m.width, m.height};
                   obstacles_.push_back(o);
                   answer(o);
                 },
                 [this](const RemoveObstacleById& m) {
                   std::erase_if(obstacles_,
                                 [&](const ObstacleRegistered& o) { return o.id == m.id; });
                 },
                 [this](const RemoveObstacleAt& m) {
                   std::erase_if(obstacles_,
                                 [&](const ObstacleRegistered& o) { return inside(o, m.x, m.y); });
                 },
                 [this](const ClearObstacles&) { obstacles_.clear(); },
             },
             request);
}

// Along the sensor's direction in 1 cm steps: the first wall or obstacle, at most the range.
std::uint16_t FakeAlphabot::distanceAt(int degree) const {
  double rad = (heading_ + degree) * M_PI / 180.0;
  double dx = std::cos(rad), dy = std::sin(rad);
  for (int d = 1; d <= kSensorRange; ++d) {
    double x = x_ + dx * d, y = y_ + dy * d;
    if (x <= 0 || y <= 0 || x >= kRoomLength || y >= kRoomWidth)
      return static_cast<std::uint16_t>(d);
    for (const auto& o : obstacles_)
      if (inside(o, x, y)) return static_cast<std::uint16_t>(d);
  }
  return kSensorRange;
}

// Straight to the target, or round the first obstacle in the way (beside it, then on).
Path FakeAlphabot::pathTo(Waypoint target) const {
  auto blocked = [this](Waypoint a, Waypoint b) -> const ObstacleRegistered* {
    for (int i = 0; i <= 100; ++i) {
      double x = a.x + (b.x - a.x) * i / 100.0, y = a.y + (b.y - a.y) * i / 100.0;
      for (const auto& o : obstacles_)
        if (inside(o, x, y)) return &o;
    }
    return nullptr;
  };
  Waypoint here{x_, y_};
  const ObstacleRegistered* o = blocked(here, target);
  if (!o) return Path{{target}};
  Waypoint beside{o->x, static_cast<std::int16_t>(o->y + o->height / 2 + 20)};
  return Path{{beside, target}};
}

}  // namespace pitwall::testing
