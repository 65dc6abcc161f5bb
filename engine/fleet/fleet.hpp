#pragma once
// The cars of one run: each an AnkiCar over the Link that owns its connection. Cars are numbered
// from 1 in the order they join. The fleet knows links, not where they lead: a simulated car
// joins with the SimLink its session made (engine/cli/session.cpp), a real one with its BLE link.
#include <functional>
#include <memory>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/core/signal.hpp"
#include "engine/vehicles/anki_car.hpp"

namespace pitwall {

class Fleet {
 public:
  explicit Fleet(Loop& loop);
  ~Fleet();
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  // Takes the link; the car is known at once and joins (carJoined) when its link first
  // connects. A link that connects when told is told after this returns, so that the fleet sees
  // the connection.
  AnkiCar& add(std::unique_ptr<Link> link, CarIdentity identity);

  const std::vector<AnkiCar*>& cars() const { return cars_; }
  AnkiCar* find(int number) const;
  std::size_t connectedCount() const;

  // Listeners (the Lua world, the MQTT bridge, the race view, --record) subscribe and hold their
  // Subscription; they are called in the order they subscribed.
  // Once per car, the first time it connects.
  Signal<AnkiCar&> carJoined;
  // Every connection change of every car, after carJoined on a first connection (the MQTT
  // bridge, the race view).
  Signal<AnkiCar&, bool /*connected*/, const std::string& /*reason*/> connectionChanged;
  // Every frame of every car, in and out (--record, the MQTT bridge, the race view).
  Signal<AnkiCar&, AnkiCar::Direction, std::span<const std::uint8_t>, const anki::Message&> frames;

  // Sends speed 0 to every connected car (shutdown, end of run, script death).
  void stopAll();
  // The end of the run: every car gets its stop and takes no command after it (AnkiCar::halt);
  // so does a car added after it.
  void haltAll();
  // Ctrl-Z (docs/safety.md): every connected car gets its stop and refuses every other command,
  // with `why`, until resumeAll(); after it they take commands again and stay stopped until one
  // comes.
  void pauseAll(const std::string& why);
  void resumeAll();

 private:
  struct Entry;
  Loop& loop_;
  bool halted_ = false;
  std::vector<std::unique_ptr<Entry>> entries_;
  std::vector<AnkiCar*> cars_;
};

}  // namespace pitwall
