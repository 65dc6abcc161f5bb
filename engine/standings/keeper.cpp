#include "engine/standings/keeper.hpp"

#include <unistd.h>

#include <ctime>
#include <fstream>

#include "engine/standings/race_json.hpp"

namespace pitwall::standings {

namespace {
constexpr const char* kUnsavedMark = "pitwall unsaved standings";
}

Result<std::unique_ptr<Keeper>, std::string> Keeper::open(const std::string& path, Event event) {
  auto db = Database::open(path);
  if (!db) return Unexpected{db.error()};
  return std::unique_ptr<Keeper>(new Keeper(std::move(*db), std::move(event)));
}

std::optional<std::string> Keeper::flush() {
  if (!id_) {
    auto id = db_->beginEvent(event_);
    if (!id) return id.error();
    id_ = *id;
  }
  while (!held_.empty()) {
    if (auto added = db_->addRace(*id_, held_.front()); !added) return added.error();
    held_.erase(held_.begin());
    ++written_;
  }
  return std::nullopt;
}

std::optional<std::string> Keeper::add(Race race) {
  // Races held already: the file was locked for the whole wait once; try again at once, and wait
  // again only at the end (a locked file must not hold a league up for the wait at every heat).
  db_->waitForLocks(held_.empty());
  held_.push_back(std::move(race));
  if (auto problem = flush())
    return *problem + "; " + std::to_string(held_.size()) +
           (held_.size() == 1 ? " race is" : " races are") +
           " held and written with the next one or at the end";
  return std::nullopt;
}

std::optional<std::string> Keeper::finish() {
  if (held_.empty() && !id_) return std::nullopt;  // nothing raced
  db_->waitForLocks(true);
  auto problem = flush();
  if (!problem) {
    if (auto ended = db_->endEvent(*id_); !ended) return ended.error();
    return std::nullopt;
  }
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%S", std::gmtime(&now));
  const std::string file =
      path() + ".unsaved-" + stamp + "-" + std::to_string(static_cast<long>(getpid())) + ".json";
  nlohmann::json races = nlohmann::json::array();
  for (const Race& r : held_) races.push_back(toJson(r));
  nlohmann::json unsaved = {{"pitwall", kUnsavedMark},
                            {"database", path()},
                            {"event", toJson(event_)},
                            {"eventId", id_ ? nlohmann::json(*id_) : nlohmann::json(nullptr)},
                            {"races", races}};
  std::ofstream out(file);
  out << unsaved.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  out.close();
  const std::string count = std::to_string(held_.size()) + (held_.size() == 1 ? " race" : " races");
  if (!out) {
    std::string text;
    for (const Race& r : held_)
      text += "\n" + toJson(r).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    return *problem + ". " + count + " could not be written to " + file +
           " either; here they are:" + text;
  }
  return *problem + ". " + count + " kept in " + file + ": add them with `pitwall standings --db " +
         path() + " import " + file + "` once the database is free";
}

Result<int, std::string> importUnsaved(Database& db, const std::string& file) {
  std::ifstream in(file);
  if (!in) return Unexpected{file + ": cannot be read"};
  auto j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object() || j.value("pitwall", std::string()) != kUnsavedMark || !j.contains("races") ||
      !j["races"].is_array())
    return Unexpected{file +
                      ": not an unsaved standings file (pitwall writes one beside the database "
                      "when it cannot write a race)"};
  auto event = eventFromJson(j.value("event", nlohmann::json::object()));
  if (!event) return Unexpected{file + ": " + event.error()};
  std::vector<Race> races;
  for (const auto& r : j["races"]) {
    auto race = raceFromJson(r);
    if (!race) return Unexpected{file + ": " + race.error()};
    races.push_back(std::move(*race));
  }
  // The event it belongs to, when this database has it; else a new one.
  std::optional<std::int64_t> id;
  if (auto known = j.find("eventId"); known != j.end() && known->is_number_integer()) {
    auto events = db.events();
    if (!events) return Unexpected{events.error()};
    for (const auto& e : *events)
      if (e.id == known->get<std::int64_t>() && e.kind == event->kind && e.title == event->title)
        id = e.id;
  }
  if (!id) {
    auto begun = db.beginEvent(*event);
    if (!begun) return Unexpected{begun.error()};
    id = *begun;
  }
  int added = 0;
  for (const Race& r : races) {
    auto written = db.addRace(*id, r);
    if (!written)
      return Unexpected{written.error() + " (" + std::to_string(added) + " of " +
                        std::to_string(races.size()) +
                        " races added before it; a race added already cannot be added twice)"};
    ++added;
  }
  if (auto ended = db.endEvent(*id); !ended) return Unexpected{ended.error()};
  return added;
}

}  // namespace pitwall::standings
