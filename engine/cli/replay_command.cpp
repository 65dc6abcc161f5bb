// pitwall replay FILE: a --record file read back through the same codec and car model as the run
// (docs/view.md "Replays"). Only the bytes of the frames from the cars are trusted; every event
// and lap is computed again. The cars are replayed, so nothing is ever sent: what a script (or
// the end of the run) commands is logged as not sent.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bindings/script_file.hpp"
#include "engine/cli/commands.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/record_source.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/record/record_player.hpp"
#include "engine/record/record_reader.hpp"

namespace pitwall::cli {

namespace {

constexpr auto kProgressEvery = std::chrono::milliseconds(100);  // the view's replay object

double micro(double seconds) {
  return std::round(seconds * 1e6) / 1e6;
}

std::string lapText(const std::vector<double>& laps, bool best) {
  if (laps.empty()) return "-";
  double v = best ? *std::min_element(laps.begin(), laps.end()) : laps.back();
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", v);
  return text;
}

// The summary per car: the laps the view's feed counted, the frames the car model saw.
void printSummary(const RecordPlayer& player, const view::Feed& feed, bool json) {
  if (!json)
    std::printf("%-4s %-16s %5s %9s %9s %8s %8s %9s %5s\n", "CAR", "NAME", "LAPS", "BEST", "LAST",
                "IN", "OUT", "MALFORMED", "DROPS");
  for (int number : player.recordedCars()) {
    const AnkiCar* car = player.car(number);
    const laps::CarTracker* tracker = feed.tracker(car->identity().number);
    static const std::vector<double> kNone;
    const std::vector<double>& laps = tracker ? tracker->lapTimes() : kNone;
    const CarState& s = car->state();
    if (json) {
      nlohmann::ordered_json times = nlohmann::ordered_json::array();
      for (double l : laps) times.push_back(micro(l));
      nlohmann::ordered_json row = {
          {"car", number},
          {"name", car->identity().name},
          {"laps", laps.size()},
          {"bestLap", laps.empty() ? nlohmann::ordered_json(nullptr)
                                   : nlohmann::ordered_json(
                                         micro(*std::min_element(laps.begin(), laps.end())))},
          {"lastLap", laps.empty() ? nlohmann::ordered_json(nullptr)
                                   : nlohmann::ordered_json(micro(laps.back()))},
          {"lapTimes", std::move(times)},
          {"framesIn", s.frames_in},
          {"framesOut", player.framesOut(number)},
          {"malformed", s.malformed},
          {"drops", s.drops},  // the record's link lines that say the link went down
          {"lastDrop", s.last_drop.empty() ? nlohmann::ordered_json(nullptr)
                                           : nlohmann::ordered_json(s.last_drop)},
      };
      std::cout << row.dump() << "\n";
    } else {
      std::printf("%-4d %-16s %5zu %9s %9s %8llu %8llu %9llu %5d\n", number,
                  printable(car->identity().name, 16).c_str(), laps.size(),
                  lapText(laps, true).c_str(), lapText(laps, false).c_str(),
                  static_cast<unsigned long long>(s.frames_in),
                  static_cast<unsigned long long>(player.framesOut(number)),
                  static_cast<unsigned long long>(s.malformed), s.drops);
    }
  }
  std::cout.flush();
}

// A control message from the page: {"pause": bool} | {"seek": seconds} | {"speed": x}. What is
// wrong is said in the view's event log (as a warning).
void control(RecordPlayer& player, const nlohmann::json& message) {
  auto refuse = [](const std::string& why) { log::warn("replay", "control refused: " + why); };
  if (auto p = message.find("pause"); p != message.end()) {
    if (!p->is_boolean()) return refuse("\"pause\" must be true or false");
    player.pause(p->get<bool>());
  }
  if (auto s = message.find("speed"); s != message.end()) {
    if (!s->is_number() || !(s->get<double>() >= 0.1 && s->get<double>() <= 100))
      return refuse("\"speed\" must be a number 0.1..100");
    player.setSpeed(s->get<double>());
  }
  if (auto s = message.find("seek"); s != message.end()) {
    if (!s->is_number() || !std::isfinite(s->get<double>()))
      return refuse("\"seek\" must be a number of seconds");
    player.seek(s->get<double>());
  }
}

}  // namespace

int replay(const ReplayOptions& options) {
  const std::string& file = options.file;
  if (!options.script.empty()) {  // refused before the record is read
    if (auto problem = script_file::check(options.script)) {
      return fail("replay", *problem);
    }
  }
  auto opened = openRecord("replay", file, options.interval);
  if (auto* status = std::get_if<int>(&opened)) return *status;
  RecordSource& source = *std::get<std::unique_ptr<RecordSource>>(opened);
  std::istream& in = *source.in;
  const RecordSummary& record = source.summary;

  // The track drawn: --track, else the record's own layout, else the default oval. A summary
  // and a script follow the cars on --track or the record's layout too, when there is one: the
  // transitions carry a car along it where position updates are missing (a real car on a curve
  // at speed), so no lap is lost.
  std::optional<sim::Track> track;
  if (!options.view && (options.track || !record.layout.empty())) {
    auto layout = options.track ? sim::loadLayout(*options.track)
                                : sim::parseLayout(record.layout, "recorded");
    if (layout)
      track = std::move(*layout);
    else if (options.track) {
      return fail("replay", layout.error());
    }
  }
  if (options.view) {
    auto layout = options.track           ? sim::loadLayout(*options.track)
                  : record.layout.empty() ? sim::loadLayout("oval")
                                          : sim::parseLayout(record.layout, "recorded");
    if (!layout) {
      return fail("replay", (options.track ? "" : "the record's layout: ") + layout.error() +
                                (options.track ? "" : "; draw another with --track LAYOUT"));
    }
    track = std::move(*layout);
  }

  // The view plays the record in real time; a summary and a script take it in virtual time.
  auto session = Session::openReplay(options.view ? ClockKind::Real : ClockKind::Virtual);
  Loop& loop = session->loop();
  view::Feed* feed = nullptr;
  if (options.view) {
    if (int status = session->startView(*options.view, "replay", "replay"); status != 0)
      return status;
    feed = session->viewFeed();
    feed->setTrack(std::move(track), "layout");
  } else {
    feed = &session->startFeed("replay");
    if (track) feed->setTrack(std::move(track), "layout");
  }

  RecordPlayer player(loop, session->fleet(), in, record);
  // The feed and the log tell the record's time; both let go of the player before it goes.
  struct Clocks {
    view::Feed* feed;
    Loop& loop;
    ~Clocks() {
      feed->setClock(nullptr);
      feed->onControl = nullptr;
      log::setTimeSource([&loop = loop] { return loop.seconds(); });
    }
  } clocks{feed, loop};
  feed->setClock([&player] { return player.position(); });
  log::setTimeSource([&player] { return player.position(); });
  player.onRewind = [feed] {
    feed->reset();
    feed->setRace(nullptr);  // the record's race lines come again from its start
  };
  // The race as the run's race library reported it (a record made with --record keeps it): the
  // view shows the title, the phases, the drivers, the gaps and the race's own laps.
  player.onSent = [feed](AnkiCar& car, const anki::Message& m) { feed->sent(car, m); };
  player.onRace = [feed](const std::string& race) {
    nlohmann::json j = nlohmann::json::parse(race, nullptr, false);
    if (j.is_object() || j.is_null()) feed->setRace(std::move(j));
  };

  const bool summary = options.summary || options.json || (!options.view && options.script.empty());
  if (options.view) {
    auto publish = [&player, feed, &file] {
      feed->setReplay({{"duration", micro(player.duration())},
                       {"position", micro(player.position())},
                       {"speed", player.speed()},
                       {"paused", player.paused()},
                       {"file", std::filesystem::path(file).filename().string()}});
    };
    feed->onControl = [&player, publish](const nlohmann::json& message) {
      control(player, message);
      publish();
    };
    // the position moves with the clock: the replay object follows it
    std::function<void()> tick;
    tick = [&loop, &tick, publish] {
      publish();
      loop.after(kProgressEvery, tick);
    };
    player.setSpeed(options.speed);
    publish();
    loop.after(kProgressEvery, tick);
    player.onEnd = [] {
      log::info("replay", "the end of the record; the view is served until Ctrl-C");
    };
    player.play();
    loop.run();  // until Ctrl-C or SIGTERM (Session::finish)
    if (summary) printSummary(player, *feed, options.json);
    return session->exitStatus(0);
  }

  if (!options.script.empty()) {
    HostOptions host;
    host.seed = options.seed;
    try {
      session->startHost(host);
    } catch (const std::exception& e) {
      const std::string why = e.what();
      session->finish();
      session->loop().run();  // a Ctrl-C while the world was made reaches the session here
      if (session->interrupted()) return session->exitStatus(1);
      return fail("replay", why, 1);
    }
    player.onEnd = [&session, &player] {
      log::info("replay",
                "the record is over (" + std::to_string(player.duration()) + " s): ending the run");
      session->finish();
    };
    auto started = session->scripts().start(options.script);
    if (!started) {
      fail("replay", started.error());
      session->finish();
      loop.run();
      return 1;
    }
    player.play();
    loop.run();  // ends through Session::finish: the record's end, pitwall.stop(), a signal
    if (summary) printSummary(player, *feed, options.json);
    return session->exitStatus(session->host().mainFailed() ? 1 : 0);
  }

  player.onEnd = [&loop] { loop.stop(); };
  player.play();
  loop.run();
  if (session->interrupted()) return 130;
  printSummary(player, *feed, options.json);
  return 0;
}

Command addReplayCommand(CLI::App& app) {
  auto replay = std::make_shared<ReplayOptions>();
  auto* cmd = app.add_subcommand(
      "replay",
      "Play a --record file back through the codec and the car model: a summary per car, the "
      "race view, or a script's handlers (docs/view.md)");
  cmd->add_option("file", replay->file,
                  "The record: JSON lines written by --record, or a capture without times "
                  "(INDEX CAR HEX… lines, or JSON lines without \"t\")")
      ->required();
  cmd->add_option("--interval", replay->interval,
                  "For a capture without times: seconds between its frames (default: inferred "
                  "from the cars' speeds and wheel distances)")
      ->check(CLI::Range(0.0001, 60.0));
  cmd->add_flag("--summary", replay->summary,
                "Print a table per car: laps, best and last lap, frames in and out, "
                "malformed frames (the default without --view and --script)");
  cmd->add_flag("--json", replay->json,
                "The summary as one JSON object per car per line instead of the table");
  auto* view = addView(cmd, replay->view);
  cmd->add_option("--speed", replay->speed, "With --view: playback speed, 0.1..100 (default 1)")
      ->check(CLI::Range(0.1, 100.0))
      ->needs(view);
  cmd->add_option("--track", replay->track,
                  "The layout the record's cars drove, a name or a file (default: the record's "
                  "own): laps are counted along it where position updates are missing; with "
                  "--view also the layout drawn (oval for a record that keeps none)");
  auto* script = cmd->add_option(
      "--script", replay->script,
      "Deliver the recorded events to this Lua script's handlers, in virtual time; its commands "
      "are logged, not sent");
  script->excludes(view);
  cmd->add_option("--seed", replay->seed, "With --script: the seed of math.random")->needs(script);
  return {cmd, [replay] { return cli::replay(*replay); }};
}

}  // namespace pitwall::cli
