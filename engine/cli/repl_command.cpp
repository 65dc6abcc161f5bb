// pitwall repl: a Lua prompt with the cars bound (docs/repl.md). The simulator runs behind it in
// real time, or real cars are driven over Bluetooth LE with --ble.
#include <iostream>
#include <memory>

#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/repl.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"

namespace pitwall::cli {

namespace {

std::string banner(const ReplOptions& options, std::size_t cars) {
  std::string where =
      options.ble ? "over Bluetooth LE" : "on the simulator (" + options.track + ", real time)";
  return "pitwall repl: " + std::to_string(cars) + (cars == 1 ? " car " : " cars ") + where +
         " as `cars`; :help for commands and keys, Ctrl-D to quit\n";
}

}  // namespace

int repl(const ReplOptions& options) {
  // Real time: the world must not race ahead while the operator types.
  auto made = Session::open(options, false, "repl");
  if (!made) return 2;
  Session& session = *made;
  Loop& loop = session.loop();
  // Until the prompt is up, Ctrl-C and SIGTERM end the start-up (the cars are stopped); once it
  // is, SIGINT is the REPL's and SIGTERM stays with the session.
  if (options.view) {
    if (int status = session.startView(*options.view, options.ble ? "ble" : "simulator", "repl");
        status != 0)
      return status;
  }
  if (int status = session.connectCars("repl"); status != 0) return status;

  HostOptions host;
  host.seed = options.seed;
  host.view = session.viewFeed();
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    const std::string why = e.what();
    session.finish();  // the cars are connected: they get their stop
    loop.run();
    // A Ctrl-C while the world was made interrupts its library's loading: no error of its own
    // (the signal reaches the session in the loop just run).
    if (!session.interrupted()) fail("repl", why);
    return session.exitStatus(1);
  }

  Repl prompt(loop, [&]() -> ScriptHost& { return session.host(); },
              {replHistoryFile(options.history)});
  prompt.onQuit = [&] { session.finish(); };
  session.releaseSigint();  // the REPL's own handler takes SIGINT from here on
  if (prompt.interactive()) prompt.print(banner(options, session.fleet().cars().size()));
  prompt.start();
  loop.run();  // ends through Session::finish: :quit, Ctrl-D, end of input, SIGTERM, pitwall.stop()
  return session.exitStatus(!prompt.interactive() && prompt.failures() > 0 ? 1 : 0);
}

Command addReplCommand(CLI::App& app) {
  auto repl = std::make_shared<ReplOptions>();
  auto* cmd = app.add_subcommand(
      "repl", "A Lua prompt with the cars bound; the simulator runs behind it in real time");
  addCarSource(cmd, *repl, "before the prompt opens");
  addRemoteCars(cmd, *repl);
  addView(cmd, repl->view);
  cmd->add_option("--history", repl->history,
                  "History file (default $PITWALL_HISTORY, else ~/.pitwall_history)");
  return {cmd, [repl] { return cli::repl(*repl); }};
}

}  // namespace pitwall::cli
