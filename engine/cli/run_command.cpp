// pitwall run SCRIPT: a script driving simulated cars (real or virtual time), or real cars over
// Bluetooth LE with --ble.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "bindings/script_file.hpp"
#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/ghost_option.hpp"
#include "engine/cli/league_final.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/repl.hpp"
#include "engine/cli/session.hpp"
#include "engine/cli/standings_keeping.hpp"
#include "engine/core/data_dir.hpp"
#include "engine/core/log.hpp"
#include "engine/core/numbers.hpp"
#include "engine/laps/trace_json.hpp"
#include "engine/record/results.hpp"
#include "engine/standings/keeper.hpp"
#include "engine/standings/race_json.hpp"

namespace pitwall::cli {

// A --fast run with no --duration whose script never ends the run (a script that drives and
// never calls pitwall.stop()) would spin at full speed for ever: this safety net stops it after
// a simulated day, and says so (issue 14). A script that ends by itself, a race of any sensible
// length, ends long before.
constexpr double kFastCap = 24 * 3600;

namespace {
// Personal bests (docs/racing.md "Personal bests"): each entry's best whole lap of this race —
// begun at its green light or after, ended by `now` — as the feed traced it, and the race's
// layout, which the best is of. An entry whose number is not the feed's car of that name gets
// none (a script's own results may number their entries otherwise); a race without its green
// light's time, none.
void traceBestLaps(standings::Race& race, const nlohmann::json& given, const view::Feed& feed,
                   double now) {
  race.layout.clear();  // (what a script sent is no trace of ours)
  for (standings::Entry& e : race.entries) e.bestTrace.reset();
  auto green = given.find("green");
  if (!feed.track() || green == given.end() || !green->is_number()) return;
  const double from = green->get<double>();
  race.layout = sim::layoutText(*feed.track());
  const auto cars = feed.tracedCars();
  for (standings::Entry& e : race.entries) {
    const auto car =
        std::find_if(cars.begin(), cars.end(), [&](const auto& c) { return c.first == e.number; });
    const auto* traces = feed.laps(e.number);
    if (car == cars.end() || car->second != e.car || !traces) continue;
    const laps::LapTrace* best = nullptr;
    for (const laps::LapTrace& lap : *traces)
      if (lap.clean && lap.start >= from - 1e-6 && lap.start + lap.time <= now + 1e-6 &&
          (!best || lap.time < best->time))
        best = &lap;
    if (best) e.bestTrace = standings::Entry::Trace{best->time, laps::traceJson(*best).dump()};
  }
}

// --driver CAR=FILE, each read and checked now (before any car is connected): the number, a file
// that exists and compiles, one file per car.
Result<std::map<int, std::string>, std::string> driverFiles(const std::vector<std::string>& given) {
  std::map<int, std::string> files;
  for (const auto& g : given) {
    const auto eq = g.find('=');
    int number = 0;
    const auto* end = eq == std::string::npos ? nullptr : g.data() + eq;
    auto [ptr, ec] = std::from_chars(g.data(), end ? end : g.data(), number);
    if (!end || ec != std::errc() || ptr != end || number < 1 || number > 64)
      return Unexpected{"--driver " + g +
                        ": expected CAR=FILE, the car's number (1..64) and a driver file, as in "
                        "--driver 2=alice.lua"};
    const std::string file = g.substr(eq + 1);
    std::error_code fsError;
    if (!std::filesystem::is_regular_file(file, fsError))
      return Unexpected{"--driver " + g + ": no such file " + file};
    if (auto problem = script_file::check(file))
      return Unexpected{"--driver " + g + ": " + *problem};
    if (files.count(number))
      return Unexpected{"--driver " + g + ": car " + std::to_string(number) +
                        " has a driver already (--driver " + std::to_string(number) + "=" +
                        files[number] + ")"};
    files[number] = std::filesystem::absolute(file, fsError).lexically_normal().string();
  }
  return files;
}

std::string simulatedTime(double seconds) {
  std::string text = formatNumber(seconds, 6) + " s";
  if (seconds >= 3600) text += " (" + formatNumber(seconds / 3600, 6) + " h)";
  return text;
}
}  // namespace

int run(const RunOptions& given) {
  RunOptions options = given;
  // A league's final: the shipped script, its drivers' files, its database (docs/league.md)
  std::optional<FinalPlan> final;
  if (!options.leagueFinal.empty()) {
    if (!options.drivers.empty())
      return fail("run",
                  "--league-final gives every car its driver: no --driver with it (the league's "
                  "files race)");
    auto plan = planFinal(options.leagueFinal, options.finalCars);
    if (!plan) return fail("run", plan.error());
    final = std::move(*plan);
    if (options.script.empty()) options.script = final->script;
    if (options.db.empty()) options.db = final->db;
    for (const auto& [number, file] : final->files)
      options.drivers.push_back(std::to_string(number) + "=" + file);
  } else if (!options.code.empty()) {
    // the view's code page (docs/classroom.md): every car's driver is its desk's file
    if (!options.drivers.empty())
      return fail("run",
                  "--code gives every car its desk's driver (FOLDER/car-N/driver.lua): no "
                  "--driver with it");
    if (!options.view)
      return fail("run",
                  "--code serves the code page on the race view: give --view too (--view "
                  "0.0.0.0:8080 for a classroom's laptops and tablets)");
    if (options.script.empty()) {
      auto data = dataDir();
      if (!data) return fail("run", data.error());
      options.script = (*data / "examples" / "classroom" / "race.lua").string();
    }
  } else if (options.script.empty()) {
    return fail("run",
                "give the script to run: pitwall run SCRIPT (or --league-final DB to race a "
                "league's final)");
  }
  // The script is read and compiled before any car is connected: a missing one (status 2) or one
  // that does not compile (status 1) is refused at once, not after a Bluetooth scan. With
  // --watch a script that does not compile yet is waited for, as before.
  if (auto problem = script_file::check(options.script)) {
    std::error_code ec;
    const bool missing = !std::filesystem::is_regular_file(options.script, ec);
    if (missing || !options.watch) {
      fail("run", *problem);
      return missing ? 2 : 1;
    }
  }
  if (!options.results.empty()) {  // refused now, not after the race
    auto checked = results::writable(options.results);
    if (!checked) {
      return fail("run", checked.error());
    }
  }
  // (a finalist's file that no longer compiles enters all the same, and is out at the start, as
  // in the league)
  auto drivers = final ? Result<std::map<int, std::string>, std::string>(final->files)
                       : driverFiles(options.drivers);
  if (!drivers) return fail("run", drivers.error());
  // The standings: a file named with --db must take the results, or the run is refused now; the
  // default one that cannot is said, and the run goes on without it.
  auto opened = openStandings(
      options.db, options.noDb,
      final ? standings::Event{"final", final->title, "",
                               nlohmann::json{{"league", final->league}}.dump()}
            : standings::Event{"race", std::filesystem::path(options.script).stem().string(), "",
                               "{}"},
      "run", {{"--record", options.record}, {"--results", options.results}},
      // (a run's loop must turn: a write waits 50 ms at most for another program's lock — its
      // own writes take milliseconds; a race the file does not take then is held, and the wait
      // for the lock comes once the cars are stopped)
      50);
  if (!opened) return fail("run", opened.error());
  std::unique_ptr<standings::Keeper> keeper = std::move(*opened);
  if (options.humans > 0 && options.fast && options.view) {  // phones live in real time
    return fail("run",
                "phones drive in real time: --humans with --view needs no --fast (a phone's "
                "second of silence would pass in an instant)");
  }
  auto made = Session::open(options, options.fast, "run");
  if (!made) return 2;
  Session& session = *made;
  if (options.fast && options.view)  // said, not refused: a script may hold the view up itself
    log::warn("pitwall",
              "--view with --fast: the race runs faster than a browser can follow; "
              "the view shows where it ends (run without --fast to watch it)");
  if (!options.record.empty()) {
    try {
      session.record(options.record);
    } catch (const std::exception& e) {
      return fail("run", e.what());
    }
  }
  Loop& loop = session.loop();
  if (!options.ghost.empty() && !options.ble && options.humans > options.cars)
    return fail("run", "--humans " + std::to_string(options.humans) + " with --ghost: car " +
                           std::to_string(options.cars + 1) +
                           " is the ghost, which no one drives; give at most --humans " +
                           std::to_string(options.cars) + " (the --cars)");
  if (!options.ghost.empty()) {  // (a record played, or the standings read: before any car)
    const sim::Track* track = session.ghostTrack();
    if (!track)
      return fail("run",
                  "--ghost with --ble needs --track LAYOUT: the layout the cars race on, which "
                  "the ghost drives");
    auto ghost = resolveGhost(options.ghost, *track, keeper ? &keeper->database() : nullptr);
    if (!ghost) return fail("run", ghost.error());
    session.setGhost(std::move(ghost->spec), ghost->what);
  }
  // Everything that can refuse the start comes before the first car is connected, and the record
  // is opened (truncated) only once nothing can: a refused start leaves an old record as it was
  // and no car driven (docs/safety.md).
  if (!options.code.empty())
    if (int status = session.openClassroom(options.code, "run"); status != 0) return status;
  if (options.view) {
    if (int status = session.startView(*options.view, options.ble ? "ble" : "simulator", "run");
        status != 0)
      return status;
  }
  if (int status = session.startSeats(options, "run"); status != 0) return status;
  if (int status = session.connectCars("run"); status != 0) return status;
  try {
    session.openRecord();
  } catch (const std::exception& e) {
    fail("run", e.what());
    session.finish();
    loop.run();
    return 2;
  }

  std::map<int, std::string> files = *drivers;
  if (session.classroom()) {  // a desk for each car, its file the car's driver
    auto desks = session.addDesks();
    if (!desks) {
      fail("run", desks.error());
      session.finish();
      loop.run();
      return 2;
    }
    files = std::move(*desks);
  }

  HostOptions host;
  host.seed = options.seed;
  host.classroom = session.classroom();
  host.results = options.results;
  host.view = session.viewFeed();  // (the view's: the script shows its race there)
  // Personal bests (docs/racing.md): each car's laps traced, so that a race kept in the
  // standings keeps each entry's best lap as a ghost can drive it again.
  view::Feed* traced = keeper ? &session.startFeed(options.ble ? "ble" : "simulator") : nullptr;
  // ...and the track's personal best, the view's reference lap until the session beats it
  if (traced && host.view && traced->track()) {
    auto kept = keptBest(keeper->database(), *traced->track(), "");
    if (!kept)
      log::warn("pitwall", kept.error());
    else if (*kept)
      traced->setPersonalBest(std::move((*kept)->lap), (*kept)->label);
  }
  host.seats = session.seats();
  host.driverFiles = files;
  host.driverLimits.memory = static_cast<std::size_t>(options.limits.driverMemory) << 20;
  host.driverLimits.budget =
      std::chrono::milliseconds(std::llround(options.limits.driverBudget * 1000));
  host.driverLimits.watch = options.watch;
  if (final)
    host.leagueFinal =
        HostOptions::LeagueFinal{final->title, final->laps, final->league, final->drivers};
  if (keeper)
    host.keepRace = [&keeper, traced,
                     &loop](const nlohmann::json& race) -> std::optional<std::string> {
      auto parsed = standings::raceFromJson(race);
      if (!parsed) {  // (kept as it came, with why, in the unsaved file at the end)
        keeper->reject(race, parsed.error());
        return "the race's results are not a race: " + parsed.error() +
               " (kept as they came beside the database)";
      }
      traceBestLaps(*parsed, race, *traced, loop.seconds());
      return keeper->add(std::move(*parsed));
    };
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    const std::string why = e.what();
    session.finish();  // the cars are connected: they get their stop
    loop.run();
    // A Ctrl-C while the world was made interrupts its library's loading: no error of its own
    // (the signal reaches the session in the loop just run).
    if (!session.interrupted()) fail("run", why);
    return session.exitStatus(1);
  }

  if (options.duration) {
    loop.after(fromSeconds(*options.duration), [&] {
      log::info("pitwall", "the run's duration is over: stopping the cars");
      session.finish();
    });
  }
  bool capped = false;
  if (!options.duration && options.fast) {
    double cap = options.fastCap.value_or(kFastCap);
    log::info("pitwall", "--fast: until the script ends, at most " + simulatedTime(cap) +
                             " simulated (--fast-cap S)");
    loop.after(fromSeconds(cap), [&session, &capped, cap] {
      capped = true;
      log::error("pitwall", "the script was still running after " + simulatedTime(cap) +
                                " of simulated time, the --fast safety cap: stopping the cars. "
                                "Give --duration S to a script that does not end the run "
                                "itself (pitwall.stop()), or --fast-cap S to one that needs "
                                "longer");
      session.finish();
    });
  }

  Reloader& scripts = session.scripts();
  scripts.keepRunningOnError(options.watch || options.repl);
  std::unique_ptr<Repl> repl;
  if (options.repl) {  // up before the script starts: what it prints goes above the prompt
    repl = std::make_unique<Repl>(
        loop, [&session]() -> ScriptHost& { return session.host(); },
        Repl::Options{replHistoryFile(options.history)});
    session.releaseSigint();  // Ctrl-C interrupts a chunk at the prompt, never the run
    repl->onQuit = [&session] { session.finish(); };
    scripts.onNewVersion = [&repl](ScriptHost&) { repl->worldChanged(); };
    repl->start();
  }
  auto started = scripts.start(options.script);
  if (!started && !options.watch) {
    fail("run", started.error());
    session.finish();
    loop.run();
    return 1;
  }
  if (options.watch) {
    if (!started)  // a broken first version: wait for a fix, as the later ones do
      log::error("pitwall", started.error() + "\n  waiting for the script to be saved again");
    if (auto watching = scripts.watch(); !watching) {
      fail("run", watching.error());
      session.finish();
      loop.run();
      return 2;
    }
    log::info("pitwall", "watching " + options.script + " and its modules: save to reload");
  }
  loop.run();  // ends through Session::finish, which every way out of a run calls
  session.loopEnded();
  repl.reset();
  const bool kept = finishStandings(keeper.get(), "run", [](const std::string& text) {
    log::info("pitwall", "the results are " + text);
  });
  if (capped) return session.exitStatus(kExitCapped);
  return session.exitStatus(session.host().mainFailed() || !kept ? 1 : 0);
}

Command addRunCommand(CLI::App& app) {
  auto run = std::make_shared<RunOptions>();
  auto* cmd =
      app.add_subcommand("run", "Run a Lua script; by default against the built-in simulator");
  cmd->add_option("script", run->script,
                  "The Lua script to run (with --league-final: the shipped final's, by default)");
  auto* fastFlag =
      cmd->add_flag("--fast", run->fast, "Virtual time: the run goes as fast as the machine can");
  auto* durationOption = cmd->add_option("--duration", run->duration,
                                         "End the run after this many seconds of engine time")
                             ->check(CLI::PositiveNumber);
  cmd->add_option("--fast-cap", run->fastCap,
                  "With --fast and no --duration: stop a script that has not ended the run after "
                  "this many simulated seconds, exit status 124 (default 86400)")
      ->check(CLI::PositiveNumber)
      ->needs(fastFlag)
      ->excludes(durationOption);
  cmd->add_option("--record", run->record, "Write every frame in and out as JSON lines to FILE");
  cmd->add_option("--results", run->results,
                  "Where the race library writes the results: FILE.json or FILE.csv");
  // Real cars run in real time.
  addCarSource(cmd, *run, "before the script starts")->excludes(fastFlag);
  // a broker lives in real time
  addRemoteCars(cmd, *run)->excludes(fastFlag);
  addView(cmd, run->view);
  addHumans(cmd, *run);
  cmd->add_option("--ghost", run->ghost,
                  "FILE[:CAR[:LAP]] | best[:NAME]: a ghost of that recorded lap, or of the "
                  "fastest personal best the standings keep on this track (of NAME, a driver or "
                  "car), drives from the green light (docs/racing.md \"Racing a ghost\")");
  auto* replFlag = cmd->add_flag("--repl", run->repl,
                                 "Open a Lua prompt beside the script, in the same Lua world");
  cmd->add_flag("--watch", run->watch,
                "Reload the script when one of its files is saved (docs/hot-reload.md)");
  cmd->add_option("--history", run->history, "With --repl: the history file")->needs(replFlag);
  cmd->add_option("--driver", run->drivers,
                  "CAR=FILE: the race's driver of car number CAR is FILE, in a Lua world of its "
                  "own that commands that car only (repeatable; docs/drivers.md)");
  addStandingsOptions(cmd, run->db, run->noDb, "the races' results");
  auto* finalOption = cmd->add_option(
      "--league-final", run->leagueFinal,
      "DB[:LEAGUE]: race the final of a league kept in DB (default: its last) with its top "
      "drivers' files, the grid by its standings (docs/league.md)");
  cmd->add_option("--final-cars", run->finalCars,
                  "With --league-final: how many of the league's top drivers race (default: as "
                  "many as its heats had)")
      ->check(CLI::Range(2, 64))
      ->needs(finalOption);
  addDriverLimits(cmd, run->limits, "each driver world");
  cmd->add_option("--code", run->code,
                  "FOLDER: serve the code page on --view: students write, test and race their "
                  "car's driver in the browser, kept in FOLDER/car-N (docs/classroom.md)")
      ->excludes(fastFlag)
      ->excludes(finalOption);
  // A prompt needs the real clock: virtual time would race ahead while the operator types.
  replFlag->excludes(fastFlag);
  // Hands on a gamepad or the keys drive in real time; the keys are the prompt's with --repl.
  cmd->get_option("--gamepads")->excludes(fastFlag);
  cmd->get_option("--keyboard")->excludes(fastFlag)->excludes(replFlag);
  return {cmd, [run] { return cli::run(*run); }};
}

}  // namespace pitwall::cli
