#pragma once
// An event's races kept in the standings as they end (docs/league.md "Standings"): each written in
// one transaction, so a killed run keeps every race it finished. A race that cannot be written now
// (the file locked, the disk full) is held and tried again with the next race and at the end; what
// still cannot be written then goes to an unsaved file beside the database, which
// `pitwall standings import FILE` adds later. No result is lost: a race that is not a race
// (a script's own call with a wrong field) is kept in that file too, with why.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/standings/database.hpp"

namespace pitwall::standings {

class Keeper {
 public:
  // Opens the database now (a sentence when it cannot be: before anything races). The event is
  // added with its first race: a run that races nothing leaves nothing. `racingWaitMs`: how long
  // a write waits for another program's lock while racing — the default wait (a league's parent:
  // nothing else runs meanwhile), or a moment (a run's loop must turn: a lock held longer holds
  // the race, and the wait comes at the end).
  static Result<std::unique_ptr<Keeper>, std::string> open(
      const std::string& path, Event event, std::optional<int> racingWaitMs = std::nullopt);

  // Writes the race; a sentence when it is held for later instead. A race whose number its
  // kind has had in this event already gets the next one (a script's second race.laps).
  std::optional<std::string> add(Race race);
  // A race that could not be read (`why`): kept as it came, in the unsaved file at the end.
  void reject(nlohmann::json race, const std::string& why);
  // Writes what is held and ends the event; a sentence naming the unsaved file when some could
  // not be written (or printing its whole text when even that file could not be).
  std::optional<std::string> finish();

  const std::string& path() const { return db_->path(); }
  Database& database() { return *db_; }  // to read from (a personal best for --ghost)
  std::optional<std::int64_t> event() const { return id_; }
  int written() const { return written_; }

 private:
  Keeper(std::unique_ptr<Database> db, Event event, std::optional<int> racingWaitMs)
      : db_(std::move(db)), event_(std::move(event)), racingWaitMs_(racingWaitMs) {}
  std::optional<std::string> flush();
  std::string unsavedText() const;

  std::unique_ptr<Database> db_;
  Event event_;
  std::optional<int> racingWaitMs_;
  std::optional<std::int64_t> id_;
  std::vector<Race> held_;
  std::vector<std::pair<nlohmann::json, std::string>> rejected_;
  std::map<std::string, int> nextNumber_;  // kind → the next number free in this event
  std::string token_;                      // this keeper's, in an unsaved file (import once)
  int written_ = 0;
};

// `pitwall standings import FILE`: an unsaved file's races into the database — into the event
// they belong to when it is there, else into one made for this file (a second import of it finds
// that one). Returns how many races were added.
Result<int, std::string> importUnsaved(const std::string& db, const std::string& file);

}  // namespace pitwall::standings
