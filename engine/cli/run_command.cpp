// pitwall run SCRIPT: a script driving simulated cars (real or virtual time), or real cars over
// Bluetooth LE with --ble.
#include <boost/asio/signal_set.hpp>
#include <cmath>
#include <csignal>
#include <iostream>

#include "bindings/interrupt.hpp"
#include "bindings/results.hpp"
#include "engine/cli/commands.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

// A --fast run with no --duration and a script that never calls pitwall.stop() would spin
// forever at full speed; it ends after this much simulated time instead.
constexpr double kFastDefaultDuration = 3600;

namespace {

// The session for the options, with its cars connected; nullptr after printing why not.
std::unique_ptr<Session> makeSession(const RunOptions& options, int& status) {
  status = 2;
  if (!options.ble) {
    auto track = sim::loadLayout(options.track);
    if (!track) {
      std::cerr << "pitwall run: " << track.error() << "\n";
      return nullptr;
    }
    return std::make_unique<Session>(options.fast ? ClockKind::Virtual : ClockKind::Real,
                                     std::move(*track), options.seed);
  }
  ble::CentralOptions central;
  central.adapters = options.adapters;
  central.cars = options.carAddresses;
  central.scan = fromSeconds(options.scanTimeout);
  try {
    return std::make_unique<Session>(std::move(central));
  } catch (const ble::BleError& e) {
    std::cerr << "pitwall run: " << e.what() << "\n";
    return nullptr;
  }
}

}  // namespace

int run(const RunOptions& options) {
  int status = 0;
  auto made = makeSession(options, status);
  if (!made) return status;
  Session& session = *made;
  status = 0;
  if (!options.results.empty()) {  // refused now, not after the race
    auto checked = results::writable(options.results);
    if (!checked) {
      std::cerr << "pitwall run: " << checked.error() << "\n";
      return 2;
    }
  }
  if (!options.record.empty()) {
    try {
      session.record(options.record);
    } catch (const std::exception& e) {
      std::cerr << "pitwall run: " << e.what() << "\n";
      return 2;
    }
  }

  Loop& loop = session.loop();
  boost::asio::signal_set signals(loop.io(), SIGINT, SIGTERM);
  std::function<void(const boost::system::error_code&, int)> onSignal =
      [&](const boost::system::error_code& ec, int sig) {
        if (ec) return;
        if (status == 130) {  // a second Ctrl-C: leave now
          loop.stop();
          return;
        }
        status = 130;
        log::warn("pitwall", std::string(sig == SIGINT ? "interrupted" : "terminated") +
                                 ": stopping the cars");
        session.finish();
        signals.async_wait(onSignal);
      };
  signals.async_wait(onSignal);

  if (options.ble) {
    auto error = session.connectRealCars();
    if (status == 130) return status;
    if (error) {
      std::cerr << "pitwall run: " << *error << "\n";
      session.finish();
      loop.run();
      return 2;
    }
  } else if (!session.addGridCars(options.cars)) {
    std::cerr << "pitwall run: not every simulated car connected\n";
    return 1;
  }

  interrupt::setBudget(std::chrono::milliseconds(std::lround(options.budget * 1000)));
  HostOptions host;
  host.seed = options.seed;
  host.results = options.results;
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    std::cerr << "pitwall run: " << e.what() << "\n";
    return 1;
  }

  std::optional<double> duration = options.duration;
  if (!duration && options.fast) {
    duration = kFastDefaultDuration;
    log::info("pitwall", "--fast without --duration: the run ends after 3600 s of simulated time");
  }
  if (duration)
    loop.after(fromSeconds(*duration), [&] {
      log::info("pitwall", "the run's duration is over: stopping the cars");
      session.finish();
    });

  Reloader& scripts = session.scripts();
  scripts.keepRunningOnError(options.watch || options.repl);
  auto started = scripts.start(options.script);
  if (!started && !options.watch) {
    std::cerr << "pitwall run: " << started.error() << "\n";
    session.finish();
    loop.run();
    return 1;
  }
  if (options.watch) {
    if (!started)  // a broken first version: wait for a fix, as the later ones do
      log::error("pitwall", started.error() + "\n  waiting for the script to be saved again");
    if (auto watching = scripts.watch(); !watching) {
      std::cerr << "pitwall run: " << watching.error() << "\n";
      session.finish();
      loop.run();
      return 2;
    }
    log::info("pitwall", "watching " + options.script + " and its modules: save to reload");
  }
  loop.run();  // ends through Session::finish, which every way out of a run calls
  signals.cancel();
  if (session.host().mainFailed()) return 1;
  return status;
}

}  // namespace pitwall::cli
