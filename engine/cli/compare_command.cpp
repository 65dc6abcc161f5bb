// pitwall compare A.jsonl[:CAR[:LAP]] B.jsonl[:CAR[:LAP]] …: laps of records side by side,
// aligned by distance along the track (docs/racing.md "Comparing laps"). Each record is played
// through the codec, the car model and the view's tracker in virtual time, as `pitwall replay`
// plays it, so a lap here is the lap the view and the replay summary count.
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/print_module.hpp"
#include "engine/cli/record_source.hpp"
#include "engine/core/printable.hpp"
#include "engine/laps/compare_report.hpp"
#include "engine/record/results.hpp"
#include "engine/view/record_laps.hpp"

namespace pitwall::cli {

namespace {

struct CompareOptions {
  std::vector<std::string> laps;  // FILE[:CAR[:LAP]], two or more
  std::string out;                // --out FILE.svg|FILE.html
  bool json = false;
  std::optional<std::string> track;  // --track: the layout, for a record that keeps none
  double step = 10;                  // --step mm
};

// The record played for its laps (view::playLaps); the exit status after a sentence when it
// cannot be.
std::variant<view::RecordLaps, int> play(const std::string& file,
                                         const std::optional<std::string>& track) {
  auto opened = openRecord("compare", file, std::nullopt);
  if (auto* status = std::get_if<int>(&opened)) return *status;
  RecordSource& source = *std::get<std::unique_ptr<RecordSource>>(opened);
  if (!track && source.summary.layout.empty())
    return fail("compare", printable(file, 200) +
                               " keeps no track layout (a record of real cars): laps are placed "
                               "on the track they drove; give it with --track LAYOUT");
  auto layout =
      track ? sim::loadLayout(*track) : sim::parseLayout(source.summary.layout, "recorded");
  if (!layout)
    return fail("compare", (track ? "" : printable(file, 200) + "'s layout: ") + layout.error());
  return view::playLaps(*source.in, source.summary, *layout, file);
}

int compare(const CompareOptions& options) {
  if (options.laps.size() < 2) return fail("compare", "give two laps or more: A.jsonl B.jsonl …");
  if (!options.out.empty()) {
    const auto ext = std::filesystem::path(options.out).extension().string();
    if (ext != ".svg" && ext != ".html" && ext != ".png")
      return fail("compare", "--out " + options.out +
                                 ": the charts are written as .svg, .png or .html (a page with "
                                 "the table); give a name ending in one of them");
  }
  std::vector<std::pair<std::string, view::LapAsk>> asks;
  for (const auto& spec : options.laps) {
    auto ask = view::splitLapSpec(spec);
    if (!ask) return fail("compare", ask.error());
    asks.push_back(std::move(*ask));
  }
  std::map<std::string, view::RecordLaps> records;  // each file played once
  for (const auto& [file, ask] : asks) {
    if (records.count(file)) continue;
    auto played = play(file, options.track);
    if (auto* status = std::get_if<int>(&played)) return *status;
    records.emplace(file, std::move(std::get<view::RecordLaps>(played)));
  }
  laps::Report report;
  const view::RecordLaps& first = records.at(asks.front().first);
  for (const auto& [file, ask] : asks) {
    const view::RecordLaps& r = records.at(file);
    if (r.layout != first.layout)
      return fail("compare", printable(file, 200) + " was driven on another track than " +
                                 printable(first.file, 200) + " (" + printable(r.layout, 80) +
                                 " against " + printable(first.layout, 80) +
                                 "): laps are compared on one track");
    auto picked = view::pickLap(r, ask);
    if (!picked) return fail("compare", picked.error(), 1);
    report.laps.push_back({picked->label, picked->trace});
  }
  laps::LapMap map(first.track);
  report.track = first.track.name() == "recorded" ? "the recorded track" : first.track.name();
  report.sections = laps::sections(first.track, map);
  std::vector<const laps::LapTrace*> traces;
  for (const auto& l : report.laps) traces.push_back(l.trace);
  report.comparison = laps::compare(traces, map, report.sections, options.step);
  if (options.json)
    std::cout << laps::reportJson(report).dump(-1, ' ', false,
                                               nlohmann::json::error_handler_t::replace)
              << "\n";
  else
    std::cout << laps::reportText(report);
  std::cout.flush();
  if (!options.out.empty()) {
    const auto ext = std::filesystem::path(options.out).extension();
    if (ext == ".png")  // (drawn by the print module's librsvg: loaded for this only)
      return runPrintModule(
          "compare", print::PngRequest{"compare", laps::reportSvg(report), options.out, 2.0});
    auto written = results::writeText(
        options.out, ext == ".svg" ? laps::reportSvg(report) : laps::reportHtml(report),
        "the comparison");
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
                  "Also write the charts: FILE.svg, FILE.png, or FILE.html (a page with the "
                  "table)");
  cmd->add_flag("--json", options->json, "The comparison as one JSON object instead of the table");
  cmd->add_option("--track", options->track,
                  "The layout the cars drove, a name or a file (default: the record's own)");
  cmd->add_option("--step", options->step,
                  "Millimetres between the points of a comparison by distance (default 10)")
      ->check(CLI::Range(1.0, 1000.0));
  return {cmd, [options] { return compare(*options); }, /*quiet=*/true};
}

}  // namespace pitwall::cli
