// pitwall compare A.jsonl[:CAR[:LAP]] B.jsonl[:CAR[:LAP]] …: laps of records side by side,
// aligned by distance along the track (docs/racing.md "Comparing laps"). Each record is played
// through the codec, the car model and the view's tracker in virtual time, as `pitwall replay`
// plays it, so a lap here is the lap the view and the replay summary count.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/record_source.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/printable.hpp"
#include "engine/laps/compare_report.hpp"
#include "engine/record/record_player.hpp"
#include "engine/record/results.hpp"

namespace pitwall::cli {

namespace {

struct CompareOptions {
  std::vector<std::string> laps;  // FILE[:CAR[:LAP]], two or more
  std::string out;                // --out FILE.svg|FILE.html
  bool json = false;
  std::optional<std::string> track;  // --track: the layout, for a record that keeps none
  double step = 10;                  // --step mm
};

// One lap asked for: the record, the car (its recorded number or name; empty: the first), the
// lap (its number; 0: the best).
struct Ask {
  std::string spec, file, car;
  int lap = 0;
};

// FILE[:CAR[:LAP]]: the longest prefix that is a file is the record (its name may hold ':').
std::optional<Ask> parseAsk(const std::string& spec, std::string& why) {
  std::error_code ec;
  std::vector<std::string> parts;
  std::string file = spec;
  for (int tail = 0; tail <= 2; ++tail) {
    if (std::filesystem::exists(file, ec)) {
      Ask a{spec, file, "", 0};
      if (parts.size() >= 1) a.car = parts.back();
      if (parts.size() == 2) {
        const std::string& lap = parts.front();
        if (lap != "best") {
          char* end = nullptr;
          errno = 0;
          const long n = std::strtol(lap.c_str(), &end, 10);
          if (lap.empty() || *end || errno || n < 1 || n > 1000000) {
            why =
                spec + ": the lap must be a number from 1 or `best`, not '" + printable(lap) + "'";
            return std::nullopt;
          }
          a.lap = static_cast<int>(n);
        }
      }
      return a;
    }
    const auto colon = file.rfind(':');
    if (colon == std::string::npos) break;
    parts.push_back(file.substr(colon + 1));
    file.resize(colon);
  }
  why = "cannot read " + spec + ": no such file (give FILE, FILE:CAR or FILE:CAR:LAP)";
  return std::nullopt;
}

struct RecordedCar {
  int number = 0;
  std::string name;
  std::vector<laps::LapTrace> laps;
};

struct Played {
  sim::Track track;
  std::string layout;  // its text: laps compared must share it
  std::vector<RecordedCar> cars;
};

// The record played through the car model and the feed's trackers in virtual time: every car's
// laps as traces. The exit status after a sentence when it cannot be.
std::variant<Played, int> play(const std::string& file, const std::optional<std::string>& track) {
  auto opened = openRecord("compare", file, std::nullopt);
  if (auto* status = std::get_if<int>(&opened)) return *status;
  RecordSource& source = *std::get<std::unique_ptr<RecordSource>>(opened);
  if (!track && source.summary.layout.empty())
    return fail("compare", file +
                               " keeps no track layout (a record of real cars): laps are placed "
                               "on the track they drove; give it with --track LAYOUT");
  auto layout =
      track ? sim::loadLayout(*track) : sim::parseLayout(source.summary.layout, "recorded");
  if (!layout) return fail("compare", (track ? "" : file + "'s layout: ") + layout.error());
  Played played;
  played.track = *layout;
  played.layout = sim::layoutText(played.track);
  auto session = Session::openReplay(ClockKind::Virtual);
  view::Feed& feed = session->startFeed("compare");
  feed.setTrack(played.track, "layout");
  RecordPlayer player(session->loop(), session->fleet(), *source.in, source.summary);
  player.onEnd = [&session] { session->loop().stop(); };
  player.play();
  session->loop().run();
  if (session->interrupted()) return 130;
  for (int number : player.recordedCars()) {
    const AnkiCar* car = player.car(number);
    RecordedCar rc{number, car->identity().name, {}};
    if (const auto* kept = feed.laps(car->identity().number))
      for (const auto& lap : *kept)
        if (lap.clean) rc.laps.push_back(lap);
    played.cars.push_back(std::move(rc));
  }
  return played;
}

std::string lapsList(const RecordedCar& car) {
  std::string out;
  for (const auto& l : car.laps) out += (out.empty() ? "" : ", ") + std::to_string(l.lap);
  return out;
}

// The lap asked for, or a sentence saying what the record has instead.
const laps::LapTrace* pick(const Ask& ask, const Played& played, std::string& label,
                           std::string& why) {
  const RecordedCar* car = nullptr;
  if (ask.car.empty()) {
    if (!played.cars.empty()) car = &played.cars.front();
  } else {
    for (const auto& c : played.cars)
      if (std::to_string(c.number) == ask.car || c.name == ask.car) car = &c;
  }
  std::string cars;
  for (const auto& c : played.cars)
    cars += (cars.empty() ? "" : ", ") + std::to_string(c.number) + " (" + printable(c.name) + ")";
  if (!car) {
    why = ask.file + " has no car '" + printable(ask.car) + "': its cars are " + cars;
    return nullptr;
  }
  const std::string who =
      ask.file + " car " + std::to_string(car->number) + " (" + printable(car->name) + ")";
  if (car->laps.empty()) {
    why = who +
          " drove no whole lap the tracker could follow from line to line (forward, on the "
          "track's map)" +
          (played.cars.size() > 1 ? "; the record's cars are " + cars : "");
    return nullptr;
  }
  const laps::LapTrace* lap = nullptr;
  if (ask.lap == 0) {
    for (const auto& l : car->laps)
      if (!lap || l.time < lap->time) lap = &l;
  } else {
    for (const auto& l : car->laps)
      if (l.lap == ask.lap) lap = &l;
    if (!lap) {
      why = who + " has no lap " + std::to_string(ask.lap) + " to compare: its whole laps are " +
            lapsList(*car) + "; ask for one of them, or `best`";
      return nullptr;
    }
  }
  label = std::filesystem::path(ask.file).filename().string() + " car " +
          std::to_string(car->number) + " (" + printable(car->name) + ") lap " +
          std::to_string(lap->lap);
  return lap;
}

int compare(const CompareOptions& options) {
  if (options.laps.size() < 2) return fail("compare", "give two laps or more: A.jsonl B.jsonl …");
  if (!options.out.empty()) {
    const auto ext = std::filesystem::path(options.out).extension().string();
    if (ext != ".svg" && ext != ".html")
      return fail("compare", "--out " + options.out +
                                 ": the charts are written as .svg or .html (a page with the "
                                 "table); give a name ending in one of them");
  }
  std::vector<Ask> asks;
  for (const auto& spec : options.laps) {
    std::string why;
    auto ask = parseAsk(spec, why);
    if (!ask) return fail("compare", why);
    asks.push_back(std::move(*ask));
  }
  std::map<std::string, Played> records;  // each file played once
  for (const auto& a : asks) {
    if (records.count(a.file)) continue;
    auto played = play(a.file, options.track);
    if (auto* status = std::get_if<int>(&played)) return *status;
    records.emplace(a.file, std::move(std::get<Played>(played)));
  }
  laps::Report report;
  const Played& first = records.at(asks.front().file);
  for (const auto& a : asks) {
    const Played& p = records.at(a.file);
    if (p.layout != first.layout)
      return fail("compare", a.file + " was driven on another track than " + asks.front().file +
                                 " (" + printable(p.layout, 80) + " against " +
                                 printable(first.layout, 80) + "): laps are compared on one track");
    std::string label, why;
    const laps::LapTrace* lap = pick(a, p, label, why);
    if (!lap) return fail("compare", why, 1);
    report.laps.push_back({label, lap});
  }
  laps::LapMap map(first.track);
  report.track = first.track.name() == "recorded" ? "the recorded track" : first.track.name();
  report.sections = laps::sections(first.track, map);
  std::vector<const laps::LapTrace*> traces;
  for (const auto& l : report.laps) traces.push_back(l.trace);
  report.comparison = laps::compare(traces, map, report.sections, options.step);
  if (options.json)
    std::cout << laps::reportJson(report).dump() << "\n";
  else
    std::cout << laps::reportText(report);
  std::cout.flush();
  if (!options.out.empty()) {
    const bool svg = std::filesystem::path(options.out).extension() == ".svg";
    auto written = results::writeText(
        options.out, svg ? laps::reportSvg(report) : laps::reportHtml(report), "the comparison");
    if (!written) return fail("compare", written.error(), 1);
  }
  return 0;
}

}  // namespace

Command addCompareCommand(CLI::App& app) {
  auto options = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand(
      "compare",
      "Two laps or more side by side, aligned by distance along the track: the time of each "
      "straight and corner, and "
      "speed, time delta and lane against distance (docs/racing.md \"Comparing laps\")");
  cmd->add_option("laps", options->laps,
                  "FILE[:CAR[:LAP]] each: a --record file, its car (number or name; default: "
                  "its first) and lap (a number or `best`, the default); the first is the "
                  "reference")
      ->required();
  cmd->add_option("--out", options->out,
                  "Also write the charts: FILE.svg, or FILE.html (a page with the table)");
  cmd->add_flag("--json", options->json, "The comparison as one JSON object instead of the table");
  cmd->add_option("--track", options->track,
                  "The layout the cars drove, a name or a file (default: the record's own)");
  cmd->add_option("--step", options->step,
                  "Millimetres between the points of a comparison by distance (default 10)")
      ->check(CLI::Range(1.0, 1000.0));
  return {cmd, [options] { return compare(*options); }, /*quiet=*/true};
}

}  // namespace pitwall::cli
