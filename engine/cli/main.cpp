// pitwall — the command line (docs/cli.md).
#include <CLI/CLI.hpp>
#include <iostream>
#include <list>

#include "engine/cli/commands.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/command_text.hpp"

namespace {

// The options that say where the cars come from, shared by `run` and `repl` (docs/cli.md).
// Returns the --ble flag.
CLI::Option* addCarSource(CLI::App* cmd, pitwall::cli::CarSource& source, const char* when) {
  cmd->add_option("--seed", source.seed, "Seed of the simulator's and the script's randomness");
  auto* cars =
      cmd->add_option("--cars", source.cars, "Number of simulated cars on the grid (default 4)")
          ->check(CLI::Range(0, 64));
  auto* track =
      cmd->add_option("--track", source.track, "Track layout: a name (oval, …) or a layout file");
  auto* ble = cmd->add_flag("--ble", source.ble,
                            "Drive real cars over Bluetooth LE (BlueZ) instead of the simulator");
  ble->excludes(cars)->excludes(track);  // real cars are on a real track
  cmd->add_option("--car", source.carAddresses, "With --ble: only this car (repeatable)")
      ->needs(ble);
  cmd->add_option("--adapter", source.adapters,
                  "With --ble: use this controller, hci0, … (repeatable; default: all)")
      ->needs(ble);
  cmd->add_option("--scan-timeout", source.scanTimeout,
                  std::string("With --ble: seconds to look for cars ") + when + " (default 5)")
      ->check(CLI::PositiveNumber)
      ->needs(ble);
  cmd->add_option("--budget", source.budget,
                  "Seconds a callback may run before it is interrupted (default 0.1; 0: no limit)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--lua-memory", source.luaMemory,
                  "MB of memory the script's Lua world may hold (default 512; 0: no limit)")
      ->check(CLI::Range(0, 1 << 20));
  return ble;
}

// --mqtt URL and how to log in; `what` says what the broker is for.
CLI::Option* addMqtt(CLI::App* cmd, pitwall::cli::MqttSettings& mqtt, double& timeout,
                     const char* what) {
  auto* url = cmd->add_option(
      "--mqtt", mqtt.url,
      std::string("MQTT broker, mqtt://HOST[:PORT] or mqtts://HOST[:PORT]: ") + what);
  cmd->add_option("--mqtt-user", mqtt.user, "Username for the broker")->needs(url);
  cmd->add_option("--mqtt-password-file", mqtt.passwordFile,
                  "File whose first line is the password (default: $PITWALL_MQTT_PASSWORD)")
      ->needs(url);
  cmd->add_option("--mqtt-ca", mqtt.caFile,
                  "With mqtts://: the CA certificate (PEM) that signed the broker's")
      ->needs(url);
  cmd->add_option("--mqtt-client-id", mqtt.clientId, "MQTT client id (default: a random one)")
      ->needs(url);
  cmd->add_option("--mqtt-max-payload", mqtt.maxPayload,
                  "Refuse a payload from the broker larger than this many bytes, unread "
                  "(default 65536)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{256} * 1024 * 1024))
      ->needs(url);
  cmd->add_option("--mqtt-timeout", timeout,
                  "Seconds to wait for the broker (and --remote-cars) at start (default 5)")
      ->check(CLI::PositiveNumber)
      ->needs(url);
  return url;
}

// Remote cars for run and repl: the cars bridged by other hosts.
CLI::Option* addRemoteCars(CLI::App* cmd, pitwall::cli::CarSource& source) {
  auto* url = addMqtt(cmd, source.mqtt, source.mqttTimeout,
                      "the cars that bridges on other hosts publish join as remote cars");
  cmd->add_option("--remote-cars", source.remoteCars,
                  "With --mqtt: wait until this many remote cars are online (default 0)")
      ->check(CLI::Range(0, 64))
      ->needs(url);
  return url;
}

// --view [[HOST:]PORT]: an option whose value may be left out. CLI11 tells whether it was given
// only after parsing, so each one is kept here and copied to its command's options then.
struct ViewOption {
  CLI::Option* option = nullptr;
  std::string value;
  std::optional<std::string>* target = nullptr;
};
std::list<ViewOption> g_views;  // a list: the options keep pointers to the values

CLI::Option* addView(CLI::App* cmd, std::optional<std::string>& target) {
  auto& v = g_views.emplace_back();
  v.target = &target;
  v.option = cmd->add_option("--view", v.value,
                             "Serve the race view in a browser on [HOST:]PORT (default "
                             "127.0.0.1:8080; PORT 0: any free port) — docs/view.md")
                 ->expected(0, 1);
  return v.option;
}

void takeViews() {
  for (auto& v : g_views)
    if (v.option->count() > 0) *v.target = v.value;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pitwall;
  CLI::App app{"pitwall — an automation engine for robot race cars, scripted in Lua"};
  app.require_subcommand(1);
  std::string logLevel;
  app.add_option("--log-level", logLevel,
                 "debug, info, warn, error or off (default: info; "
                 "warn for `test`)");

  cli::RunOptions run;
  auto* runCmd =
      app.add_subcommand("run", "Run a Lua script; by default against the built-in simulator");
  runCmd->add_option("script", run.script, "The Lua script to run")->required();
  auto* fastFlag =
      runCmd->add_flag("--fast", run.fast, "Virtual time: the run goes as fast as the machine can");
  auto* durationOption = runCmd
                             ->add_option("--duration", run.duration,
                                          "End the run after this many seconds of engine time")
                             ->check(CLI::PositiveNumber);
  runCmd
      ->add_option("--fast-cap", run.fastCap,
                   "With --fast and no --duration: stop a script that has not ended the run after "
                   "this many simulated seconds, exit status 124 (default 86400)")
      ->check(CLI::PositiveNumber)
      ->needs(fastFlag)
      ->excludes(durationOption);
  runCmd->add_option("--record", run.record, "Write every frame in and out as JSON lines to FILE");
  runCmd->add_option("--results", run.results,
                     "Where the race library writes the results: FILE.json or FILE.csv");
  // Real cars run in real time.
  addCarSource(runCmd, run, "before the script starts")->excludes(fastFlag);
  // a broker lives in real time
  addRemoteCars(runCmd, run)->excludes(fastFlag);

  addView(runCmd, run.view);
  auto* replFlag = runCmd->add_flag("--repl", run.repl,
                                    "Open a Lua prompt beside the script, in the same Lua world");
  runCmd->add_flag("--watch", run.watch,
                   "Reload the script when one of its files is saved (docs/hot-reload.md)");
  runCmd->add_option("--history", run.history, "With --repl: the history file")->needs(replFlag);
  // A prompt needs the real clock: virtual time would race ahead while the operator types.
  replFlag->excludes(fastFlag);

  cli::ReplOptions repl;
  auto* replCmd = app.add_subcommand(
      "repl", "A Lua prompt with the cars bound; the simulator runs behind it in real time");
  addCarSource(replCmd, repl, "before the prompt opens");
  addRemoteCars(replCmd, repl);
  addView(replCmd, repl.view);
  replCmd->add_option("--history", repl.history,
                      "History file (default $PITWALL_HISTORY, else ~/.pitwall_history)");

  cli::BridgeOptions bridge;
  auto* bridgeCmd = app.add_subcommand("bridge",
                                       "Publish the cars (simulated, or --ble) on an MQTT broker "
                                       "and execute intents (docs/mqtt.md)");
  addCarSource(bridgeCmd, bridge, "before the bridge starts");
  addMqtt(bridgeCmd, bridge.mqtt, bridge.mqttTimeout, "where the cars are published")->required();
  bridgeCmd->add_option("--host-id", bridge.hostId,
                        "The <host> of Anki/Host/<host>/… (default: this machine's host name)");
  addView(bridgeCmd, bridge.view);
  bridgeCmd->add_flag("--read-only", bridge.readOnly, "Publish only; never execute intents");
  bridgeCmd->add_option("--duration", bridge.duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);

  cli::ViewOptions spectator;
  auto* viewCmd = app.add_subcommand(
      "view", "Watch the cars that bridges publish on an MQTT broker in the race view, read-only");
  addMqtt(viewCmd, spectator.mqtt, spectator.mqttTimeout, "where bridges publish their cars")
      ->required();
  viewCmd->add_option("--track", spectator.track,
                      "The layout drawn: a name (oval, …) or a layout file (default oval)");
  addView(viewCmd, spectator.view);
  viewCmd->add_option("--duration", spectator.duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);

  cli::ScanOptions scan;
  auto* scanCmd = app.add_subcommand("scan", "List the Anki cars in Bluetooth range");
  scanCmd->add_option("--timeout", scan.timeout, "Seconds to listen (default 5)")
      ->check(CLI::PositiveNumber);
  scanCmd->add_flag("--json", scan.json, "JSON lines instead of a table");
  scanCmd->add_option("--adapter", scan.adapters, "Use this controller, hci0, … (repeatable)");

  cli::EmulateOptions emulate;
  auto* emulateCmd = app.add_subcommand(
      "emulate-car", "Be an Anki car: a BLE peripheral driven by the simulator (needs BlueZ)");
  emulateCmd->add_option("--adapter", emulate.adapter, "The controller to advertise on (hci0)");
  emulateCmd->add_option("--name", emulate.name, "The car's user name (pitwall, ≤ 12 bytes)");
  emulateCmd->add_flag("--plain-name", emulate.plainName,
                       "Advertise the user name alone, not laid out as a car's local name");
  emulateCmd->add_option("--model", emulate.model, "Model id (8: Groundshock)")
      ->check(CLI::Range(1, 255));
  emulateCmd->add_option("--track", emulate.track, "Track layout the car drives on (oval)");
  emulateCmd->add_option("--seed", emulate.seed, "Seed of the simulator");
  emulateCmd->add_option("--duration", emulate.duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);

  cli::SimRobotOptions robot;
  auto* robotCmd = app.add_subcommand(
      "sim-robot", "Be a seed robot (mindroad or alphabot), simulated, listening on the network");
  robotCmd->add_option("kind", robot.kind, "mindroad or alphabot")->required();
  robotCmd->add_option("--listen", robot.listen,
                       "HOST:PORT to listen on (default 127.0.0.1:0: a free port, printed)");
  robotCmd->add_flag("--udp", robot.udp, "mindroad: UDP instead of TCP");
  robotCmd
      ->add_option("--watchdog", robot.watchdog,
                   "mindroad: seconds without an instruction before the robot stops (0.5)")
      ->check(CLI::PositiveNumber);
  robotCmd->add_option("--seed", robot.seed, "Seed of the simulation's noise");
  robotCmd->add_option("--room", robot.room, "alphabot: a room file (docs/robots.md)");
  robotCmd->add_option("--duration", robot.duration, "Stop after this many seconds")
      ->check(CLI::PositiveNumber);

  cli::TestOptions test;
  auto* testCmd = app.add_subcommand("test", "Run scenario test scripts in virtual time");
  testCmd->add_option("paths", test.paths, "Scenario files, or folders of *_test.lua files");
  testCmd->add_option("--seed", test.seed, "Seed of the simulator's and the scripts' randomness");
  testCmd->add_option("--timeout", test.timeout, "Virtual seconds a scenario may run (default 600)")
      ->check(CLI::PositiveNumber);
  testCmd
      ->add_option("--budget", test.budget,
                   "Seconds a callback may run before it is interrupted (default 0.1; 0: no limit)")
      ->check(CLI::NonNegativeNumber);
  testCmd
      ->add_option("--lua-memory", test.luaMemory,
                   "MB of memory a scenario's Lua world may hold (default 512; 0: no limit)")
      ->check(CLI::Range(0, 1 << 20));

  cli::ReplayOptions replay;
  auto* replayCmd = app.add_subcommand(
      "replay",
      "Play a --record file back through the codec and the car model: a summary per car, the "
      "race view, or a script's handlers (docs/view.md)");
  replayCmd->add_option("file", replay.file, "The record: JSON lines written by --record")
      ->required();
  replayCmd->add_flag("--summary", replay.summary,
                      "Print a table per car: laps, best and last lap, frames in and out, "
                      "malformed frames (the default without --view and --script)");
  replayCmd->add_flag("--json", replay.json,
                      "The summary as one JSON object per car per line instead of the table");
  auto* replayView = addView(replayCmd, replay.view);
  replayCmd
      ->add_option("--speed", replay.speed, "With --view: playback speed, 0.1..100 (default 1)")
      ->check(CLI::Range(0.1, 100.0))
      ->needs(replayView);
  replayCmd
      ->add_option("--track", replay.track,
                   "With --view: the layout drawn, a name or a file (default: the record's own; "
                   "oval for a record that keeps none)")
      ->needs(replayView);
  auto* replayScript = replayCmd->add_option(
      "--script", replay.script,
      "Deliver the recorded events to this Lua script's handlers, in virtual time; its commands "
      "are logged, not sent");
  replayScript->excludes(replayView);
  replayCmd->add_option("--seed", replay.seed, "With --script: the seed of math.random")
      ->needs(replayScript);

  cli::TrackShowOptions trackShow;
  auto* trackCmd = app.add_subcommand("track", "Track layouts");
  trackCmd->require_subcommand(1);
  auto* trackShowCmd = trackCmd->add_subcommand(
      "show", "Describe a layout and draw it as the race view does: pitwall track show oval");
  trackShowCmd
      ->add_option("layout", trackShow.layout,
                   "A layout name (oval, kidney, long) or a layout file")
      ->required();
  trackShowCmd->add_option("--svg", trackShow.svg, "Write the drawing as SVG to OUT (- : stdout)");

  std::string protocol;
  std::vector<std::string> words;
  auto* decodeCmd = app.add_subcommand("decode", "Decode one frame: pitwall decode anki \"01 17\"");
  decodeCmd->add_option("protocol", protocol, "Protocol (anki, mindroad, alphabot, alphabot-ble)")
      ->required();
  decodeCmd->add_option("hex", words, "The frame's bytes in hex")->required();
  auto* encodeCmd =
      app.add_subcommand("encode", "Encode one command: pitwall encode anki set-speed 600 1000");
  encodeCmd->add_option("protocol", protocol, "Protocol (anki, mindroad, alphabot)")->required();
  encodeCmd->add_option("message", words, "The command and its arguments")->required();
  std::string forms;
  for (const auto& f : anki::commandForms()) forms += "\n  " + f;
  encodeCmd->footer("Commands (anki):" + forms);
  // Negative numbers (set-offset -23.5) are arguments, not options.
  for (auto* c : {decodeCmd, encodeCmd}) c->positionals_at_end(false);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; every usage error is status 2 (docs/cli.md), not CLI11's own.
    return app.exit(e) == 0 ? 0 : 2;
  }

  takeViews();
  bool testing = testCmd->parsed();
  if (!logLevel.empty()) {
    auto level = log::parseLevel(logLevel);
    if (!level) {
      std::cerr << "pitwall: --log-level '" << logLevel
                << "' is unknown; use debug, info, warn, error or off\n";
      return 2;
    }
    log::setLevel(*level);
  } else if (testing) {
    log::setLevel(log::Level::Warn);
  }

  if (runCmd->parsed()) return cli::run(run);
  if (replCmd->parsed()) return cli::repl(repl);
  if (bridgeCmd->parsed()) return cli::bridge(bridge);
  if (viewCmd->parsed()) return cli::view(spectator);
  if (scanCmd->parsed()) return cli::scan(scan);
  if (emulateCmd->parsed()) return cli::emulateCar(emulate);
  if (robotCmd->parsed()) return cli::simRobot(robot);
  if (replayCmd->parsed()) return cli::replay(replay);
  if (trackShowCmd->parsed()) return cli::trackShow(trackShow);
  if (testing) {
    if (test.paths.empty()) test.paths.push_back("tests/scenarios");
    return cli::test(test);
  }
  if (decodeCmd->parsed()) return cli::decode(protocol, words);
  if (encodeCmd->parsed()) return cli::encode(protocol, words);
  return 2;
}
