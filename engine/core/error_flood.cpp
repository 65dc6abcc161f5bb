#include "engine/core/error_flood.hpp"

#include "engine/core/log.hpp"

namespace pitwall {

ErrorFlood::ErrorFlood(Loop& loop, std::string component, Duration period)
    : loop_(loop), component_(std::move(component)), period_(period) {}

ErrorFlood::~ErrorFlood() {
  flush();
}

bool ErrorFlood::admit(const std::string& where, const std::string& message) {
  const TimePoint now = loop_.now();
  auto it = places_.find(where);
  if (it != places_.end() && now - it->second.last < period_) {
    Place& place = it->second;
    ++place.count;
    place.latest = message;
    place.last = now;
    return false;
  }
  if (it != places_.end()) {  // quiet for a whole period: a new flood, if it is one
    summarise(where, it->second);
    loop_.cancel(it->second.tick);
    places_.erase(it);
  }
  Place& place = places_[where];
  place.last = now;
  place.tick = loop_.after(period_, [this, where] { tick(where); });
  return true;
}

void ErrorFlood::tick(const std::string& where) {
  auto it = places_.find(where);
  if (it == places_.end()) return;
  Place& place = it->second;
  if (place.count == 0) {  // nothing from here for a whole period: the flood is over
    places_.erase(it);
    return;
  }
  summarise(where, place);
  place.tick = loop_.after(period_, [this, where] { tick(where); });
}

void ErrorFlood::summarise(const std::string& where, Place& place) {
  if (place.count == 0) return;
  std::string latest = place.latest.substr(0, place.latest.find('\n'));
  log::error(component_, where + " failed " + std::to_string(place.count) +
                             (place.count == 1 ? " more time: " : " more times: ") + latest);
  place.count = 0;
}

void ErrorFlood::flush() {
  for (auto& [where, place] : places_) {
    summarise(where, place);
    loop_.cancel(place.tick);
  }
  places_.clear();
}

}  // namespace pitwall
