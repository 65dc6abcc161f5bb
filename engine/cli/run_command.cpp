// pitwall run SCRIPT: a script driving simulated cars, in real or virtual time.
#include <boost/asio/signal_set.hpp>
#include <csignal>
#include <iostream>

#include "engine/cli/commands.hpp"
#include "engine/cli/sim_run.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

// A --fast run with no --duration and a script that never calls pitwall.stop() would spin
// forever at full speed; it ends after this much simulated time instead.
constexpr double kFastDefaultDuration = 3600;

int run(const RunOptions& options) {
  auto track = sim::loadLayout(options.track);
  if (!track) {
    std::cerr << "pitwall run: " << track.error() << "\n";
    return 2;
  }
  SimRun session(options.fast ? ClockKind::Virtual : ClockKind::Real, std::move(*track),
                 options.seed);
  if (!options.record.empty()) {
    try {
      session.record(options.record);
    } catch (const std::exception& e) {
      std::cerr << "pitwall run: " << e.what() << "\n";
      return 2;
    }
  }
  if (!session.addGridCars(options.cars)) {
    std::cerr << "pitwall run: not every simulated car connected\n";
    return 1;
  }
  HostOptions host;
  host.seed = options.seed;
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    std::cerr << "pitwall run: " << e.what() << "\n";
    return 1;
  }

  Loop& loop = session.loop();
  int status = 0;
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

  auto started = session.host().startFile(options.script);
  if (!started) {
    std::cerr << "pitwall run: " << started.error() << "\n";
    session.finish();
    loop.run();
    return 1;
  }
  loop.run();  // ends through SimRun::finish, which every way out of a run calls
  signals.cancel();
  if (session.host().mainFailed()) return 1;
  return status;
}

}  // namespace pitwall::cli
