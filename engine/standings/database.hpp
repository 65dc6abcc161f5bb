#pragma once
// Standings that last (docs/league.md "Standings"): every race and league's results in a local
// SQLite database, so a season spans many evenings. One file; its schema versioned
// (PRAGMA user_version) and migrated forward when opened; each race written in one transaction,
// so a killed run loses nothing it had finished. Every failure is a sentence naming the file, what
// is wrong and what to do — a corrupt, locked, read-only or newer file included.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/core/result.hpp"

struct sqlite3;

namespace pitwall::standings {

// The schema this build writes. 1: events, races, results; 2: a result's reason and driver file,
// and every lap's time; 3: personal bests as traces (best_laps).
inline constexpr int kSchemaVersion = 3;

// The default database: $PITWALL_DB, else $XDG_DATA_HOME/pitwall/standings.db, else
// $HOME/.local/share/pitwall/standings.db; empty when none of them is set. A write waits 10 s
// (or $PITWALL_DB_WAIT s) for another program's lock.
std::string defaultPath();

// One car's result in one race.
struct Entry {
  int number = 0;      // the car's number in the race
  std::string driver;  // who: a league's driver, a driver file's name, a player, or the car
  std::string car;     // the car's name
  std::string file;    // the driver's file, when it has one (a league's entries)
  std::optional<int> position;
  bool finished = false;
  std::string status = "finished";  // finished, DNF, DNS, …
  std::string reason;               // why it is out
  int laps = 0;
  std::optional<double> bestLap, totalTime;
  std::vector<double> lapTimes;
  // Its best whole lap as a trace (laps::traceJson), when the run traced it: its driver's
  // personal best in this car on the race's layout when it beats the one kept.
  struct Trace {
    double time = 0;
    std::string json;
  };
  std::optional<Trace> bestTrace;
};

// One race (a heat, a qualifying run, a final, a race of `pitwall run`).
struct Race {
  std::string kind = "race";  // race, heat, final (points), qualifying, practice (no points)
  int number = 1;             // its number in its event
  std::string track;
  int laps = 0;
  std::vector<Entry> entries;
  std::string layout = {};  // the track's layout text (sim::layoutText): what personal bests are of
};

// An event: a league, a `pitwall run`, a final. details: JSON (a league's options).
struct Event {
  std::string kind = "race";  // race, league, final
  std::string title;
  std::string track;
  std::string details = "{}";
};

// What the tables show: everything, or one track's or one driver's.
struct Filter {
  std::optional<std::string> track;
  std::optional<std::string> driver;
  std::optional<std::int64_t> event;
};

struct TableRow {
  std::string driver;
  int points = 0, races = 0, wins = 0, podiums = 0, finishes = 0;
  std::optional<double> bestLap;
};

// A driver's best lap on a track: the personal best, and where it was set.
struct Best {
  std::string driver, track, car, when, event;
  double lap = 0;
};

// A personal best as kept: whose, in which car, on which track, and the lap (laps::traceJson).
struct KeptLap {
  std::string driver, car, track, when;
  double lap = 0;
  std::string trace;
};

// One race of a driver's history.
struct Past {
  std::string when, event, kind, track, car, status;
  int number = 0, points = 0;
  std::optional<int> position;
  std::optional<double> bestLap;
};

struct EventInfo {
  std::int64_t id = 0;
  std::string kind, title, track, started, ended;  // ended: empty while running (or killed)
  int races = 0;
  std::string details;  // JSON
};

// A league's drivers, qualifying and heats as stored, for its standings and its final.
struct StoredLeague {
  EventInfo event;
  std::string details;  // its options (JSON)
  struct Driver {
    std::string name, file;
    std::optional<double> qualifying;
  };
  std::vector<Driver> drivers;  // by name
  struct Place {
    std::string driver;
    int position = 0;
    bool finished = false;
    std::optional<double> bestLap;
  };
  std::vector<std::vector<Place>> heats;
};

class Database {
 public:
  // Opens (creating it and its folder when `create`) and migrates the file to kSchemaVersion;
  // checks that it is whole (a corrupt file is found here, before a race, not after it).
  static Result<std::unique_ptr<Database>, std::string> open(const std::string& path,
                                                             bool create = true);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  const std::string& path() const { return path_; }
  // How long a write waits for another program's lock: the default (10 s, $PITWALL_DB_WAIT), or
  // `ms` (a run's loop while its cars race: a moment; a keeper that holds races already: none).
  void waitForLocks(bool wait);
  void waitForLocks(int ms);
  int versionFound() const { return found_; }  // the schema it had when opened (0: new)

  Result<std::int64_t, std::string> beginEvent(const Event& event);
  Result<bool, std::string> addRace(std::int64_t event, const Race& race);  // one transaction
  Result<bool, std::string> hasRace(std::int64_t event, const std::string& kind, int number);
  Result<bool, std::string> endEvent(std::int64_t event);

  Result<std::vector<TableRow>, std::string> table(const Filter& filter);
  Result<std::vector<Best>, std::string> bests(const Filter& filter);
  // The fastest personal bests kept on `layout` (at most `most`, fastest first) — of the driver
  // or car named `who`, or anyone's when it is empty.
  Result<std::vector<KeptLap>, std::string> bestLaps(const std::string& layout,
                                                     const std::string& who, int most = 20);
  Result<std::vector<Past>, std::string> history(const std::string& driver);
  Result<std::vector<EventInfo>, std::string> events();
  // The league event `id`, or the last league that ended when none is given.
  Result<StoredLeague, std::string> league(std::optional<std::int64_t> id);

 private:
  Database(sqlite3* db, std::string path) : db_(db), path_(std::move(path)) {}
  Result<bool, std::string> migrate();
  Result<bool, std::string> checkTables();
  Result<bool, std::string> probeWrite();
  std::string sentence(int code, const std::string& doing) const;

  sqlite3* db_;
  std::string path_;
  int found_ = 0;
  int waitMs_ = 0;  // what a write waits for a lock now
};

// Points for a place in a race of `kind` (league::pointsFor for races, heats and finals; none
// for qualifying and practice).
int pointsFor(const std::string& kind, std::optional<int> position, bool finished);

}  // namespace pitwall::standings
