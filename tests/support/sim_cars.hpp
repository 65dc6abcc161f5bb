#pragma once
// A simulated car on a fleet, as the session adds one (engine/cli/session.cpp addGridCars): put
// in the world, reached through a SimLink, connected once the fleet listens to it.
#include <memory>

#include "engine/fleet/fleet.hpp"
#include "engine/sim/world.hpp"
#include "engine/transport/sim_link.hpp"

namespace pitwall::testing {

inline AnkiCar& addSimulatedCar(Loop& loop, Fleet& fleet, sim::World& world,
                                const sim::CarSpec& spec) {
  sim::SimCar& simCar = world.addCar(spec);
  auto link = std::make_unique<SimLink>(loop, simCar);
  SimLink& toCar = *link;
  AnkiCar& car =
      fleet.add(std::move(link), CarIdentity{0, spec.name, spec.model_id, simCar.identifier()});
  toCar.connect();
  return car;
}

}  // namespace pitwall::testing
