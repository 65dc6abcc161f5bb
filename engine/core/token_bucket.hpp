#pragma once
// Rate limits for what arrives from outside — over MQTT (docs/mqtt.md "Hostile input"), from a
// page on the race view's WebSocket (docs/view.md) — a token bucket on the engine clock. Anyone
// who can publish on the broker or open the page can send a flood of messages, while a car's BLE
// link takes about 20–50 commands a second; and an answer to every message of a flood would be a
// flood of its own.
#include <algorithm>

#include "engine/core/loop.hpp"

namespace pitwall {

struct RateLimit {
  double perSecond = 50;  // the sustained rate: tokens added a second
  double burst = 20;      // the bucket's size: how many at once after a quiet spell
};

class TokenBucket {
 public:
  // True, and one token fewer, when a token is left at `now`; a new bucket is full.
  bool take(const RateLimit& limit, TimePoint now) {
    tokens_ = started_ ? std::min(limit.burst, tokens_ + limit.perSecond * toSeconds(now - last_))
                       : limit.burst;
    started_ = true;
    last_ = now;
    if (tokens_ < 1) return false;
    tokens_ -= 1;
    return true;
  }

 private:
  double tokens_ = 0;
  TimePoint last_{};
  bool started_ = false;
};

}  // namespace pitwall
