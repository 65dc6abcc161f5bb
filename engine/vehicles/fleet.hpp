#pragma once
// The cars of one run: each an AnkiCar over the Link that owns its connection. Cars are numbered
// from 1 in the order they join. Simulated cars join through a SimLink.
#include <functional>
#include <memory>
#include <vector>

#include "engine/core/loop.hpp"
#include "engine/sim/world.hpp"
#include "engine/vehicles/anki_car.hpp"

namespace pitwall {

class Fleet {
 public:
  explicit Fleet(Loop& loop);
  ~Fleet();
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  // Takes the link; the car is known at once and joins (onCar) when its link first connects.
  AnkiCar& add(std::unique_ptr<Link> link, CarIdentity identity);
  // A simulated car placed in `world`, connected through a SimLink.
  AnkiCar& addSimulated(sim::World& world, const sim::CarSpec& spec);

  const std::vector<AnkiCar*>& cars() const { return cars_; }
  AnkiCar* find(int number) const;
  std::size_t connectedCount() const;

  // Called once per car, the first time it connects.
  std::function<void(AnkiCar&)> onCar;
  // Every connection change of every car, after the car's own handler (the MQTT bridge).
  std::function<void(AnkiCar&, bool connected, const std::string& reason)> onConnectionChange;
  // Every frame of every car (for --record, and the MQTT bridge).
  std::function<void(AnkiCar&, AnkiCar::Direction, std::span<const std::uint8_t>,
                     const anki::Message&)>
      onFrame;

  // Sends speed 0 to every connected car (shutdown, end of run, script death).
  void stopAll();
  // The end of the run: every car gets its stop and takes no command after it (AnkiCar::halt);
  // so does a car added after it.
  void haltAll();

 private:
  struct Entry;
  Loop& loop_;
  bool halted_ = false;
  std::vector<std::unique_ptr<Entry>> entries_;
  std::vector<AnkiCar*> cars_;
};

}  // namespace pitwall
