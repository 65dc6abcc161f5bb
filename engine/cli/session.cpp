#include "engine/cli/session.hpp"

#include <cmath>
#include <csignal>
#include <iostream>

#include "bindings/interrupt.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"
#include "engine/sim/grid.hpp"

namespace pitwall::cli {

// Long enough for a frame to cross the simulator link and be acted on.
constexpr Duration kFlush = std::chrono::milliseconds(100);

Session::Session(ClockKind clock, sim::Track track, std::uint64_t seed)
    : loop_(clock), fleet_(loop_) {
  sim_.seed = seed;
  sim_.world = std::make_unique<sim::World>(loop_, std::move(track), seed);
  log::setTimeSource([this] { return loop_.seconds(); });
}

Session::Session(ble::CentralOptions options) : loop_(ClockKind::Real), fleet_(loop_) {
  log::setTimeSource([this] { return loop_.seconds(); });
  central_ = std::make_unique<ble::Central>(loop_, fleet_, std::move(options));
}

Session::~Session() {
  if (signals_) {
    boost::system::error_code ignored;
    signals_->cancel(ignored);
  }
  scripts_.reset();
  central_.reset();
  log::setTimeSource(nullptr);
}

std::unique_ptr<Session> Session::open(const CarSource& source, bool fast, const char* command) {
  std::unique_ptr<Session> session;
  if (!source.ble) {
    auto track = sim::loadLayout(source.track);
    if (!track) {
      std::cerr << "pitwall " << command << ": " << track.error() << "\n";
      return nullptr;
    }
    session = std::make_unique<Session>(fast ? ClockKind::Virtual : ClockKind::Real,
                                        std::move(*track), source.seed);
  } else {
    ble::CentralOptions central;
    central.adapters = source.adapters;
    central.cars = source.carAddresses;
    central.scan = fromSeconds(source.scanTimeout);
    try {
      session = std::make_unique<Session>(std::move(central));
    } catch (const ble::BleError& e) {
      std::cerr << "pitwall " << command << ": " << e.what() << "\n";
      return nullptr;
    }
  }
  session->source_ = source;
  session->catchSignals();
  interrupt::setBudget(std::chrono::milliseconds(std::llround(source.budget * 1000)));
  return session;
}

void Session::catchSignals() {
  signals_ = std::make_unique<boost::asio::signal_set>(loop_.io(), SIGINT, SIGTERM);
  awaitSignal();
}

void Session::awaitSignal() {
  signals_->async_wait([this](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    if (interrupted_) {  // a second one: leave now
      loop_.stop();
      return;
    }
    interrupted_ = true;
    log::warn("pitwall",
              std::string(sig == SIGINT ? "interrupted" : "terminated") + ": stopping the cars");
    finish();
    awaitSignal();
  });
}

void Session::releaseSigint() {
  boost::system::error_code ignored;
  if (signals_) signals_->remove(SIGINT, ignored);
}

int Session::connectCars(const char* command) {
  if (source_.ble) {
    auto error = connectRealCars();
    if (interrupted_) return 130;
    if (error) {
      std::cerr << "pitwall " << command << ": " << *error << "\n";
      finish();
      loop_.run();
      return 2;
    }
    return 0;
  }
  if (!addGridCars(source_.cars)) {
    if (interrupted_) return 130;
    std::cerr << "pitwall " << command << ": not every simulated car connected\n";
    return 1;
  }
  return 0;
}

void Session::record(const std::string& path) {
  recorder_ = std::make_unique<Recorder>(path);
  fleet_.onFrame = [this](AnkiCar& car, AnkiCar::Direction d, std::span<const std::uint8_t> f,
                          const anki::Message& m) {
    recorder_->write(loop_.seconds(), car.identity().number, d == AnkiCar::Direction::Tx, f, m);
  };
}

bool Session::addGridCars(int count) {
  std::vector<std::string> names;
  for (int i = 0; i < count; ++i) {
    sim::CarSpec spec = sim::gridSpec(sim_.world->track(), i);
    spec.name = anki::uniqueCarName(spec.model_id, names);
    names.push_back(spec.name);
    fleet_.addSimulated(*sim_.world, spec);
  }
  if (count == 0) return true;
  auto previous = fleet_.onCar;
  fleet_.onCar = [&](AnkiCar&) {
    if (fleet_.connectedCount() == static_cast<std::size_t>(count)) loop_.stop();
  };
  auto timeout = loop_.after(std::chrono::seconds(5), [this] { loop_.stop(); });
  loop_.run();
  loop_.cancel(timeout);
  fleet_.onCar = previous;
  return fleet_.connectedCount() == static_cast<std::size_t>(count);
}

std::optional<std::string> Session::connectRealCars() {
  std::optional<std::string> result = "interrupted";
  central_->start([&](std::optional<std::string> error) {
    result = std::move(error);
    loop_.stop();
  });
  loop_.run();
  return result;
}

void Session::startHost(HostOptions options) {
  scripts_ =
      std::make_unique<Reloader>(loop_, fleet_, sim_.world ? &sim_ : nullptr, std::move(options));
  scripts_->onStopRequested = [this] { finish(); };
}

void Session::finish() {
  if (finishing_) return;
  finishing_ = true;
  fleet_.stopAll();
  loop_.after(kFlush, [this] {
    if (!central_) return loop_.stop();
    central_->shutdown([this] { loop_.stop(); });
  });
}

}  // namespace pitwall::cli
