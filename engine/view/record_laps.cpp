#include "engine/view/record_laps.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "engine/core/log.hpp"
#include "engine/core/printable.hpp"
#include "engine/laps/ghost.hpp"
#include "engine/record/record_player.hpp"
#include "engine/view/feed.hpp"

namespace pitwall::view {

RecordLaps playLaps(std::istream& in, const RecordSummary& summary, const sim::Track& track,
                    std::string file) {
  // the cars' greetings ("connected") are the record's, not news for whoever asked
  struct Quiet {
    log::Level was = log::level();
    Quiet() {
      if (was < log::Level::Warn) log::setLevel(log::Level::Warn);
    }
    ~Quiet() { log::setLevel(was); }
  } quiet;
  RecordLaps out;
  out.file = std::move(file);
  out.track = track;
  out.layout = sim::layoutText(track);
  Loop loop(ClockKind::Virtual);
  Fleet fleet(loop);
  Feed feed(loop, fleet, "record");
  feed.setTrack(track, "layout");
  {
    RecordPlayer player(loop, fleet, in, summary);
    player.onEnd = [&loop] { loop.stop(); };
    player.play();
    loop.run();
    for (int number : player.recordedCars()) {
      const AnkiCar* car = player.car(number);
      RecordedCarLaps c{number, car->identity().name, {}};
      if (const auto* kept = feed.laps(car->identity().number))
        for (const auto& lap : *kept)
          if (lap.clean) c.laps.push_back(lap);
      out.cars.push_back(std::move(c));
    }
  }
  return out;
}

Result<std::pair<std::string, LapAsk>, std::string> splitLapSpec(const std::string& spec) {
  std::error_code ec;
  std::vector<std::string> parts;  // the tail, last first
  std::string file = spec;
  for (int tail = 0; tail <= 2; ++tail) {
    if (!file.empty() && std::filesystem::exists(file, ec)) {
      LapAsk ask;
      if (!parts.empty()) ask.car = parts.back();
      if (parts.size() == 2 && parts.front() != "best") {
        const std::string& lap = parts.front();
        char* end = nullptr;
        errno = 0;
        const long n = std::strtol(lap.c_str(), &end, 10);
        if (lap.empty() || *end || errno || n < 1 || n > 1000000)
          return Unexpected{spec + ": the lap must be a number from 1 or `best`, not '" +
                            printable(lap, 40) + "'"};
        ask.lap = static_cast<int>(n);
      }
      return std::pair{file, ask};
    }
    const auto colon = file.rfind(':');
    if (colon == std::string::npos) break;
    parts.push_back(file.substr(colon + 1));
    file.resize(colon);
  }
  return Unexpected{"cannot read " + printable(spec, 200) +
                    ": no such file (give FILE, FILE:CAR or FILE:CAR:LAP)"};
}

Result<PickedLap, std::string> pickLap(const RecordLaps& record, const LapAsk& ask) {
  const RecordedCarLaps* car = nullptr;
  if (ask.car.empty()) {
    if (!record.cars.empty()) car = &record.cars.front();
  } else {  // its number, else its name (which must then be one car's)
    for (const auto& c : record.cars)
      if (std::to_string(c.number) == ask.car) car = &c;
    int named = 0;
    for (const auto& c : record.cars)
      if (!car && c.name == ask.car) ++named;
    for (const auto& c : record.cars)
      if (!car && named == 1 && c.name == ask.car) car = &c;
    if (named > 1)
      return Unexpected{printable(record.file, 200) + " has " + std::to_string(named) +
                        " cars named '" + printable(ask.car, 40) + "': ask for one by its number"};
  }
  std::string cars;
  for (const auto& c : record.cars)
    cars += (cars.empty() ? "" : ", ") + std::to_string(c.number) + " (" + printable(c.name) + ")";
  if (!car)
    return Unexpected{printable(record.file, 200) + " has no car '" + printable(ask.car, 40) +
                      "': its cars are " + cars};
  const std::string who = printable(record.file, 200) + " car " + std::to_string(car->number) +
                          " (" + printable(car->name) + ")";
  if (car->laps.empty())
    return Unexpected{who +
                      " drove no whole lap the tracker could follow from line to line (forward, "
                      "on the track's map)" +
                      (record.cars.size() > 1 ? "; the record's cars are " + cars : "")};
  const laps::LapTrace* lap = nullptr;
  if (ask.lap == 0) {
    for (const auto& l : car->laps)
      if (!lap || l.time < lap->time) lap = &l;
  } else {
    for (const auto& l : car->laps)
      if (l.lap == ask.lap) lap = &l;
    if (!lap) {
      std::string list;
      for (const auto& l : car->laps) list += (list.empty() ? "" : ", ") + std::to_string(l.lap);
      return Unexpected{who + " has no lap " + std::to_string(ask.lap) + ": its whole laps are " +
                        list + "; ask for one of them, or `best`"};
    }
  }
  return PickedLap{lap, car,
                   printable(std::filesystem::path(record.file).filename().string(), 200) +
                       " car " + std::to_string(car->number) + " (" + printable(car->name) +
                       ") lap " + std::to_string(lap->lap)};
}

Result<RecordLaps, std::string> readRecordLaps(const std::string& path,
                                               const std::optional<std::string>& track,
                                               std::uintmax_t maxBytes) {
  std::error_code ec;
  const std::string shown = printable(path, 200);
  if (!std::filesystem::is_regular_file(path, ec))
    return Unexpected{"cannot read " + shown + ": " +
                      (std::filesystem::exists(path, ec) ? "not a file" : "no such file")};
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return Unexpected{"cannot read " + shown + ": " + ec.message()};
  if (size > maxBytes)
    return Unexpected{shown + " is " + std::to_string((size + 1023) / 1024) +
                      " KB, more than the " + std::to_string(maxBytes / 1024) +
                      " KB a ghost's record may be (it is read within the script's budget): "
                      "record the lap on its own, e.g. a time trial of that driver with --record"};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Unexpected{"cannot read " + shown};
  RecordSummary summary = scanRecord(in);
  if (summary.frames == 0)
    return Unexpected{shown + " has no frame; a record is what `pitwall run --record FILE` writes"};
  if (!track && summary.layout.empty())
    return Unexpected{shown +
                      " keeps no track layout (a record of real cars): a ghost drives a lap "
                      "recorded in the simulator, whose records keep their track"};
  auto layout = track ? sim::loadLayout(*track) : sim::parseLayout(summary.layout, "recorded");
  if (!layout) return Unexpected{(track ? "" : shown + "'s layout: ") + layout.error()};
  in.clear();
  in.seekg(0);
  return playLaps(in, summary, *layout, path);
}

Result<Ghost, std::string> ghostSpec(const std::string& path, const LapAsk& ask,
                                     const sim::Track& track, const std::vector<std::string>& taken,
                                     std::uintmax_t maxBytes) {
  auto laps = readRecordLaps(path, std::nullopt, maxBytes);
  if (!laps) return Unexpected{laps.error()};
  if (laps->layout != sim::layoutText(track))
    return Unexpected{printable(path, 200) + " was driven on " + printable(laps->layout, 80) +
                      ", and this run's track is " + printable(sim::layoutText(track), 80) +
                      ": a ghost drives the track it was on"};
  auto picked = pickLap(*laps, ask);
  if (!picked) return Unexpected{picked.error()};
  return ghostOf(*picked->trace, picked->label, track, taken);
}

Result<Ghost, std::string> ghostOf(const laps::LapTrace& lap, const std::string& label,
                                   const sim::Track& track, const std::vector<std::string>& taken) {
  char took[96];
  std::snprintf(took, sizeof took, "%.3f s for %.0f mm", lap.time, lap.length);
  if (!(lap.time * sim::GhostLap::kMaxSpeed >= lap.length))
    return Unexpected{label + " took " + took + ", faster than any car (" +
                      std::to_string(static_cast<int>(sim::GhostLap::kMaxSpeed)) +
                      " mm/s): the record's times are wrong; pick another lap"};
  Ghost g;
  g.spec.piece_index = track.finishIndex();
  auto ghost = std::make_shared<sim::GhostLap>(laps::ghostLap(lap));
  g.spec.offset_mm = ghost->lanes.empty() ? 0 : ghost->lanes.front().offset;  // on the road
  g.spec.ghost = std::move(ghost);
  g.spec.name = "ghost";
  for (int n = 2; std::find(taken.begin(), taken.end(), g.spec.name) != taken.end(); ++n)
    g.spec.name = "ghost" + std::to_string(n);
  std::snprintf(took, sizeof took, ", %.3f s", lap.time);
  g.what = label + took;
  return g;
}

}  // namespace pitwall::view
