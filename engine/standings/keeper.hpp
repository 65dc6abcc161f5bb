#pragma once
// An event's races kept in the standings as they end (docs/league.md "Standings"): each written in
// one transaction, so a killed run keeps every race it finished. A race that cannot be written now
// (the file locked for longer than the wait, the disk full) is held and tried again with the next
// race and at the end; what still cannot be written then goes to an unsaved file beside the
// database, which `pitwall standings import FILE` adds later. No result is lost.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/standings/database.hpp"

namespace pitwall::standings {

class Keeper {
 public:
  // Opens the database now (a sentence when it cannot be: before anything races). The event is
  // added with its first race: a run that races nothing leaves nothing.
  static Result<std::unique_ptr<Keeper>, std::string> open(const std::string& path, Event event);

  // Writes the race; a sentence when it is held for later instead.
  std::optional<std::string> add(Race race);
  // Writes what is held and ends the event; a sentence naming the unsaved file when some could
  // not be written (or where they are when even that file could not be).
  std::optional<std::string> finish();

  const std::string& path() const { return db_->path(); }
  std::optional<std::int64_t> event() const { return id_; }
  int written() const { return written_; }

 private:
  Keeper(std::unique_ptr<Database> db, Event event)
      : db_(std::move(db)), event_(std::move(event)) {}
  std::optional<std::string> flush();

  std::unique_ptr<Database> db_;
  Event event_;
  std::optional<std::int64_t> id_;
  std::vector<Race> held_;
  int written_ = 0;
};

// `pitwall standings import FILE`: an unsaved file's races into the database — into the event
// they belong to when it is there, else as a new one. Returns how many races were added.
Result<int, std::string> importUnsaved(Database& db, const std::string& file);

}  // namespace pitwall::standings
