#include "engine/fleet/fleet.hpp"

#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"

namespace pitwall {

struct Fleet::Entry {
  std::unique_ptr<Link> link;
  std::unique_ptr<AnkiCar> car;
  bool joined = false;
  Subscription connection;  // the fleet's, first of the car's connection listeners
};

Fleet::Fleet(Loop& loop) : loop_(loop) {}
Fleet::~Fleet() = default;

AnkiCar& Fleet::add(std::unique_ptr<Link> link, CarIdentity identity) {
  auto entry = std::make_unique<Entry>();
  identity.number = static_cast<int>(entries_.size()) + 1;
  if (identity.name.empty()) identity.name = "car" + std::to_string(identity.number);
  entry->link = std::move(link);
  entry->car = std::make_unique<AnkiCar>(loop_, *entry->link, std::move(identity));
  Entry* e = entry.get();
  AnkiCar& car = *e->car;
  if (halted_) (void)car.halt();  // a car that joins after the end of the run obeys nothing
  // A Lua world that takes the car in carJoined subscribes to its connection too, after the
  // fleet: it hears of the connections from the next one on (Signal's rules).
  e->connection = car.connectionChanged.connect([this, e](bool up, const std::string& reason) {
    if (up && !e->joined) {
      e->joined = true;
      carJoined.emit(*e->car);
    }
    connectionChanged.emit(*e->car, up, reason);
  });
  car.onFrame = [this, e](AnkiCar::Direction d, std::span<const std::uint8_t> f,
                          const anki::Message& m) { frames.emit(*e->car, d, f, m); };
  entries_.push_back(std::move(entry));
  cars_.push_back(&car);
  return car;
}

AnkiCar* Fleet::find(int number) const {
  if (number < 1 || number > static_cast<int>(cars_.size())) return nullptr;
  return cars_[number - 1];
}

std::size_t Fleet::connectedCount() const {
  std::size_t n = 0;
  for (auto* c : cars_) n += c->state().connected ? 1 : 0;
  return n;
}

void Fleet::stopAll() {
  for (auto* car : cars_)
    if (car->state().connected)
      if (auto sent = car->stop(); !sent) log::warn(car->label(), sent.error());
}

void Fleet::pauseAll(const std::string& why) {
  for (auto* car : cars_)
    if (auto sent = car->pause(why); !sent) log::warn(car->label(), sent.error());
}

void Fleet::resumeAll() {
  for (auto* car : cars_) car->resume();
}

void Fleet::haltAll() {
  halted_ = true;
  for (auto* car : cars_)
    if (auto sent = car->halt(); !sent) log::warn(car->label(), sent.error());
}

}  // namespace pitwall
