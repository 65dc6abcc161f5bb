#include "engine/standings/keeper.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "engine/standings/race_json.hpp"

namespace pitwall::standings {

namespace {

constexpr const char* kUnsavedMark = "pitwall unsaved standings";
constexpr std::uintmax_t kMaxUnsaved = std::uintmax_t{64} << 20;

std::string stamp() {
  char text[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(text, sizeof text, "%Y%m%dT%H%M%S", std::gmtime(&now));
  return text;
}

}  // namespace

Result<std::unique_ptr<Keeper>, std::string> Keeper::open(const std::string& path, Event event,
                                                          std::optional<int> racingWaitMs) {
  auto db = Database::open(path);
  if (!db) return Unexpected{db.error()};
  std::unique_ptr<Keeper> keeper(new Keeper(std::move(*db), std::move(event), racingWaitMs));
  keeper->token_ = stamp() + "-" + std::to_string(static_cast<long>(getpid()));
  return keeper;
}

// Every held race tried, each on its own: one that fails does not keep the others back.
// After the first failure the others are tried without waiting for a lock again (one wait in
// all, not one a race).
std::optional<std::string> Keeper::flush() {
  if (!id_) {
    // (the event carries this keeper's token: an unsaved file of it, imported, finds it)
    Event marked = event_;
    auto details = nlohmann::json::parse(marked.details, nullptr, false);
    if (!details.is_object()) details = nlohmann::json::object();
    details["token"] = token_;
    marked.details = details.dump();
    auto id = db_->beginEvent(marked);
    if (!id) return id.error();
    id_ = *id;
  }
  std::optional<std::string> problem;
  std::vector<Race> still;
  for (Race& race : held_) {
    if (auto added = db_->addRace(*id_, race); !added) {
      if (!problem) problem = added.error();
      db_->waitForLocks(false);
      still.push_back(std::move(race));
    } else {
      ++written_;
    }
  }
  held_ = std::move(still);
  return problem;
}

std::optional<std::string> Keeper::add(Race race) {
  int& next = nextNumber_[race.kind];
  if (race.number < next) race.number = next;
  next = race.number + 1;
  // Races held already: the file was locked for the whole wait once; try again at once, and wait
  // again only at the end (a locked file must not hold a league up for the wait at every heat).
  if (!held_.empty())
    db_->waitForLocks(false);
  else if (racingWaitMs_)
    db_->waitForLocks(*racingWaitMs_);
  else
    db_->waitForLocks(true);
  held_.push_back(std::move(race));
  if (auto problem = flush())
    return *problem + "; " + std::to_string(held_.size()) +
           (held_.size() == 1 ? " race is" : " races are") +
           " held and written with the next one or at the end";
  return std::nullopt;
}

void Keeper::reject(nlohmann::json race, const std::string& why) {
  rejected_.emplace_back(std::move(race), why);
}

std::string Keeper::unsavedText() const {
  nlohmann::json races = nlohmann::json::array();
  for (const Race& r : held_) races.push_back(toJson(r));
  nlohmann::json rejected = nlohmann::json::array();
  for (const auto& [race, why] : rejected_) rejected.push_back({{"why", why}, {"race", race}});
  nlohmann::json unsaved = {{"pitwall", kUnsavedMark},
                            {"database", path()},
                            {"token", token_},
                            {"event", toJson(event_)},
                            {"eventId", id_ ? nlohmann::json(*id_) : nlohmann::json(nullptr)},
                            {"races", races}};
  if (!rejected.empty()) unsaved["rejected"] = rejected;
  return unsaved.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::optional<std::string> Keeper::finish() {
  if (held_.empty() && rejected_.empty() && !id_) return std::nullopt;  // nothing raced
  // What is held is saved beside the database first: a wait for a lock that a second Ctrl-C cuts
  // short loses nothing. It goes once everything is in.
  const std::string file = path() + ".unsaved-" + token_ + ".json";
  bool saved = false;
  if (!held_.empty() || !rejected_.empty()) {
    std::ofstream out(file);
    out << unsavedText();
    out.close();
    saved = static_cast<bool>(out);
    if (!saved)
      std::filesystem::remove(file);  // (a file cut short by a full disk reads as nothing)
  }
  db_->waitForLocks(true);
  auto problem = flush();
  if (!problem) {
    if (auto ended = db_->endEvent(*id_); !ended) problem = ended.error();
  }
  if (!problem && rejected_.empty()) {
    if (saved) std::filesystem::remove(file);
    return std::nullopt;
  }
  if (saved && !problem) {  // everything written but the races that were not races
    std::ofstream(file) << unsavedText();
    return std::to_string(rejected_.size()) +
           (rejected_.size() == 1 ? " race was" : " races were") +
           " not kept, as they were not races (" + rejected_.front().second + "): kept in " + file;
  }
  const std::string count = std::to_string(held_.size()) + (held_.size() == 1 ? " race" : " races");
  if (saved) {
    std::ofstream(file) << unsavedText();  // (what is still held now)
    return *problem + ". " + count + " kept in " + file +
           ": add them with `pitwall standings --db " + path() + " import " + file +
           "` once the database is free";
  }
  return *problem + ". " + count + " could not be saved beside it either (" + file +
         "); here is that file's text, for `pitwall standings import`:\n" + unsavedText();
}

Result<int, std::string> importUnsaved(const std::string& dbPath, const std::string& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec || !std::filesystem::exists(status))
    return Unexpected{file + ": cannot be read (" +
                      (ec ? ec.message() : std::string("no such file")) + ")"};
  if (!std::filesystem::is_regular_file(status))
    return Unexpected{file + ": not a file (an unsaved standings file is a JSON file)"};
  const auto size = std::filesystem::file_size(file, ec);
  if (ec || size > kMaxUnsaved)
    return Unexpected{file + ": " + (ec ? ec.message() : std::to_string(size >> 20) + " MB") +
                      ": an unsaved standings file is at most 64 MB"};
  std::ifstream in(file, std::ios::binary);
  if (!in) return Unexpected{file + ": cannot be read (" + std::strerror(errno) + ")"};
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {
    return Unexpected{file + ": not JSON (" + std::string(e.what()) +
                      "): an unsaved standings file is JSON, as pitwall wrote it"};
  }
  const auto mark = j.is_object() ? j.find("pitwall") : j.end();
  if (!j.is_object() || mark == j.end() || !mark->is_string() || *mark != kUnsavedMark ||
      !j.contains("races") || !j["races"].is_array())
    return Unexpected{file +
                      ": not an unsaved standings file (pitwall writes one beside the database "
                      "when it cannot write a race)"};
  static const nlohmann::json kNoEvent = nlohmann::json::object();
  const auto ev = j.find("event");
  auto event = eventFromJson(ev == j.end() ? kNoEvent : *ev);
  if (!event) return Unexpected{file + ": " + event.error()};
  std::vector<Race> races;
  for (const auto& r : j["races"]) {
    auto race = raceFromJson(r);
    if (!race) return Unexpected{file + ": " + race.error()};
    races.push_back(std::move(*race));
  }
  std::string token;
  if (auto t = j.find("token"); t != j.end() && t->is_string()) token = t->get<std::string>();
  auto opened = Database::open(dbPath);  // (only now: a file refused above leaves no database)
  if (!opened) return Unexpected{opened.error()};
  Database& db = **opened;
  // The event it belongs to, when this database has it; else the one an earlier import of this
  // file made; else a new one, marked with the file's token.
  std::optional<std::int64_t> id;
  auto events = db.events();
  if (!events) return Unexpected{events.error()};
  if (auto known = j.find("eventId"); known != j.end() && known->is_number_integer())
    for (const auto& e : *events)
      if (e.id == known->get<std::int64_t>() && e.kind == event->kind && e.title == event->title)
        id = e.id;
  if (!id && !token.empty())
    for (const auto& e : *events) {
      const auto details = nlohmann::json::parse(e.details, nullptr, false);
      if (details.is_object() && details.contains("token") && details["token"] == token) id = e.id;
    }
  if (races.empty()) return 0;
  if (!id) {
    auto details = nlohmann::json::parse(event->details, nullptr, false);
    if (!details.is_object()) details = nlohmann::json::object();
    if (!token.empty()) details["token"] = token;
    event->details = details.dump();
    auto begun = db.beginEvent(*event);
    if (!begun) return Unexpected{begun.error()};
    id = *begun;
  }
  // A race its event has already (an import cut short and done again, a run that wrote it after
  // all) is left out: a race is kept once
  int added = 0, there = 0;
  for (const Race& r : races) {
    auto has = db.hasRace(*id, r.kind, r.number);
    if (!has) return Unexpected{has.error()};
    if (*has) {
      ++there;
      continue;
    }
    auto written = db.addRace(*id, r);
    if (!written)
      return Unexpected{written.error() + " (" + std::to_string(added) + " of " +
                        std::to_string(races.size()) +
                        " races added before it: import the file again once that is mended)"};
    ++added;
  }
  if (added == 0 && there > 0)
    return Unexpected{file + ": its " + std::to_string(there) +
                      (there == 1 ? " race is" : " races are") + " in " + dbPath +
                      " already: a race is kept once"};
  if (auto ended = db.endEvent(*id); !ended) return Unexpected{ended.error()};
  return added;
}

}  // namespace pitwall::standings
