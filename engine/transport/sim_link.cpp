#include "engine/transport/sim_link.hpp"

#include <algorithm>
#include <cstdio>

namespace pitwall {

SimLink::SimLink(Loop& loop, sim::SimCar& car, Duration latency)
    : loop_(loop),
      car_(car),
      latency_(std::max(latency, Duration::zero())),
      alive_(std::make_shared<bool>(true)),
      carLife_(car.lifetime()) {
  if (loop.clockKind() == ClockKind::Real) setConnectionInterval(kRealTimeInterval);
}

void SimLink::setConnectionInterval(Duration interval) {
  interval_ = std::max(interval, Duration::zero());
  phase_ = interval_.count() > 0
               ? Duration(static_cast<Duration::rep>(car_.identifier()) % interval_.count())
               : Duration::zero();
}

SimLink::~SimLink() {
  // The controller goes away: the car notices and stops, as on a lost BLE connection. Pending
  // timers die with us; posted state reports see alive_ expire and do nothing.
  if (toCarTimer_) loop_.cancel(toCarTimer_);
  if (toControllerTimer_) loop_.cancel(toControllerTimer_);
  if (retryTimer_) loop_.cancel(retryTimer_);
  if (connected_) {
    connected_ = false;
    car_.disconnect();
  }
}

void SimLink::connect() {
  if (connected_) return;
  connected_ = true;  // before the car speaks: it sends its status on connect
  reportState(true, "connected");
  car_.connect(
      [this](std::span<const std::uint8_t> frame) {
        if (connected_) enqueue(toController_, toControllerTimer_, false, frame);
      },
      [this] {
        lost("the car disconnected");
        retryLater();
      });
}

void SimLink::retryLater() {
  if (retryTimer_) return;
  retryTimer_ = loop_.after(kRetry, [this] {
    retryTimer_ = 0;
    if (connected_ || carLife_.expired()) return;
    if (car_.connectable())
      connect();
    else
      retryLater();
  });
}

bool SimLink::send(std::span<const std::uint8_t> frame) {
  if (!connected_ || frame.size() > anki::Frame::kMax) return false;
  enqueue(toCar_, toCarTimer_, true, frame);
  return true;
}

void SimLink::disconnect() {
  if (retryTimer_) loop_.cancel(retryTimer_);  // the controller's own: it stays down
  retryTimer_ = 0;
  if (!connected_) return;
  lost("disconnected by the controller");
  car_.disconnect();
}

std::string SimLink::address() const {
  char buf[16];
  std::snprintf(buf, sizeof buf, "sim:%08x", static_cast<unsigned>(car_.identifier()));
  return buf;
}

void SimLink::enqueue(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar,
                      std::span<const std::uint8_t> frame) {
  TimePoint due = loop_.now() + latency_;
  if (interval_.count() > 0) {  // the next connection event: later frames never come earlier
    const auto since = (due - TimePoint{} - phase_).count();
    const auto events = (since + interval_.count() - 1) / interval_.count();
    due = TimePoint{} + phase_ + interval_ * std::max<Duration::rep>(events, 0);
  }
  InFlight f{due, {}};
  std::copy(frame.begin(), frame.end(), f.frame.bytes.begin());
  f.frame.length = static_cast<std::uint8_t>(frame.size());
  queue.push_back(f);
  arm(queue, timer, toCar);
}

void SimLink::arm(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar) {
  if (timer || queue.empty()) return;
  // Due times never fall as frames are queued (a fixed latency, then the next event at or
  // after it): the queue stays sorted and order is preserved.
  if (toCar)
    timer = loop_.at(queue.front().due, [this] { deliverToCar(); });
  else
    timer = loop_.at(queue.front().due, [this] { deliverToController(); });
}

void SimLink::deliverToCar() {
  deliver(toCar_, toCarTimer_, true);
}
void SimLink::deliverToController() {
  deliver(toController_, toControllerTimer_, false);
}

void SimLink::deliver(std::deque<InFlight>& queue, Loop::TimerId& timer, bool toCar) {
  timer = 0;
  TimePoint now = loop_.now();
  // Pop before delivering: the car may drop the connection (0x0d) and the frame handler may
  // send or disconnect, from inside the call; a drop clears the queues.
  while (connected_ && !queue.empty() && queue.front().due <= now) {
    anki::Frame frame = queue.front().frame;
    queue.pop_front();
    if (toCar)
      car_.receive(frame.span());
    else
      deliverFrame(frame.span());
  }
  arm(queue, timer, toCar);
}

void SimLink::lost(const std::string& reason) {
  if (!connected_) return;
  connected_ = false;
  toCar_.clear();
  toController_.clear();
  if (toCarTimer_) loop_.cancel(toCarTimer_);
  if (toControllerTimer_) loop_.cancel(toControllerTimer_);
  toCarTimer_ = toControllerTimer_ = 0;
  reportState(false, reason);
}

void SimLink::reportState(bool up, std::string reason) {
  std::weak_ptr<bool> alive = alive_;
  loop_.post([this, alive, up, reason = std::move(reason)] {
    if (alive.expired()) return;
    deliverState(up, reason);
  });
}

}  // namespace pitwall
