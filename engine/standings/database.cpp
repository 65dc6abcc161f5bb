#include "engine/standings/database.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>

#include "engine/core/numbers.hpp"
#include "engine/league/scoring.hpp"

namespace pitwall::standings {

namespace fs = std::filesystem;

namespace {

// How long a write waits for another program's lock before it is a sentence: 10 s, or
// $PITWALL_DB_WAIT seconds (0 to 600).
int busyMs() {
  if (const char* env = std::getenv("PITWALL_DB_WAIT"); env && *env) {
    char* end = nullptr;
    const double s = std::strtod(env, &end);
    if (end && *end == 0 && s >= 0 && s <= 600) return static_cast<int>(s * 1000);
  }
  return 10000;
}

// Each step takes the schema from version k to k+1 (kMigrations[k]). A step is never changed once
// released: a new schema is a new step.
constexpr std::array<const char*, kSchemaVersion> kMigrations = {
    // 1: events, their races, each car's result
    R"(CREATE TABLE events(
         id INTEGER PRIMARY KEY,
         kind TEXT NOT NULL,
         title TEXT NOT NULL,
         track TEXT NOT NULL,
         started TEXT NOT NULL,
         ended TEXT,
         details TEXT NOT NULL DEFAULT '{}');
       CREATE TABLE races(
         id INTEGER PRIMARY KEY,
         event INTEGER NOT NULL REFERENCES events(id),
         kind TEXT NOT NULL,
         number INTEGER NOT NULL,
         track TEXT NOT NULL,
         laps INTEGER NOT NULL,
         ended TEXT NOT NULL,
         UNIQUE(event, kind, number));
       CREATE TABLE results(
         race INTEGER NOT NULL REFERENCES races(id),
         number INTEGER NOT NULL,
         driver TEXT NOT NULL,
         car TEXT NOT NULL,
         position INTEGER,
         finished INTEGER NOT NULL,
         status TEXT NOT NULL,
         laps INTEGER NOT NULL,
         best_lap REAL,
         total_time REAL,
         points INTEGER NOT NULL,
         PRIMARY KEY(race, number));
       CREATE INDEX results_driver ON results(driver);)",
    // 2: why a car is out, the driver's file (a league's final races the same files), each lap
    R"(ALTER TABLE results ADD COLUMN reason TEXT NOT NULL DEFAULT '';
       ALTER TABLE results ADD COLUMN file TEXT NOT NULL DEFAULT '';
       CREATE TABLE laps(
         race INTEGER NOT NULL REFERENCES races(id),
         number INTEGER NOT NULL,
         lap INTEGER NOT NULL,
         time REAL NOT NULL,
         PRIMARY KEY(race, number, lap));)",
    // 3: personal bests: each driver's best lap in each car on each layout, as a trace a ghost
    // drives again (laps::traceJson)
    R"(CREATE TABLE best_laps(
         driver TEXT NOT NULL,
         car TEXT NOT NULL,
         layout TEXT NOT NULL,
         track TEXT NOT NULL,
         lap REAL NOT NULL,
         trace TEXT NOT NULL,
         event INTEGER REFERENCES events(id),
         set_at TEXT NOT NULL,
         PRIMARY KEY(driver, car, layout));)",
};

// A prepared statement, finalized when it goes.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr); }
  ~Statement() { sqlite3_finalize(s_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  int prepared() const { return rc_; }
  sqlite3_stmt* raw() { return s_; }

  void bind(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(s_, i, v); }
  void bind(int i, int v) { sqlite3_bind_int(s_, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(s_, i, v); }
  void bind(int i, const std::optional<double>& v) {
    v ? sqlite3_bind_double(s_, i, *v) : sqlite3_bind_null(s_, i);
  }
  void bind(int i, const std::optional<int>& v) {
    v ? sqlite3_bind_int(s_, i, *v) : sqlite3_bind_null(s_, i);
  }
  void bind(int i, const std::optional<std::string>& v) {
    v ? bind(i, *v) : static_cast<void>(sqlite3_bind_null(s_, i));
  }
  int step() { return sqlite3_step(s_); }
  void reset() {
    sqlite3_reset(s_);
    sqlite3_clear_bindings(s_);
  }

  std::string text(int c) const {
    const auto* p = sqlite3_column_text(s_, c);
    return p ? std::string(reinterpret_cast<const char*>(p),
                           static_cast<std::size_t>(sqlite3_column_bytes(s_, c)))
             : std::string();
  }
  int integer(int c) const { return sqlite3_column_int(s_, c); }
  std::int64_t integer64(int c) const { return sqlite3_column_int64(s_, c); }
  bool null(int c) const { return sqlite3_column_type(s_, c) == SQLITE_NULL; }
  std::optional<double> real(int c) const {
    if (null(c)) return std::nullopt;
    return sqlite3_column_double(s_, c);
  }
  std::optional<int> optionalInt(int c) const {
    if (null(c)) return std::nullopt;
    return integer(c);
  }

 private:
  sqlite3_stmt* s_ = nullptr;
  int rc_ = SQLITE_OK;
};

std::string where(const Filter& f, bool& any) {
  std::string w;
  auto add = [&](const char* clause) {
    w += any ? " AND " : " WHERE ";
    w += clause;
    any = true;
  };
  if (f.track) add("ra.track = :track");
  if (f.driver) add("r.driver = :driver");
  if (f.event) add("ra.event = :event");
  return w;
}

void bindFilter(sqlite3_stmt* s, const Filter& f) {
  auto named = [&](const char* name) { return sqlite3_bind_parameter_index(s, name); };
  if (f.track)
    sqlite3_bind_text(s, named(":track"), f.track->data(), static_cast<int>(f.track->size()),
                      SQLITE_TRANSIENT);
  if (f.driver)
    sqlite3_bind_text(s, named(":driver"), f.driver->data(), static_cast<int>(f.driver->size()),
                      SQLITE_TRANSIENT);
  if (f.event) sqlite3_bind_int64(s, named(":event"), *f.event);
}

}  // namespace

std::string defaultPath() {
  if (const char* env = std::getenv("PITWALL_DB"); env && *env) return env;
  if (const char* data = std::getenv("XDG_DATA_HOME"); data && *data)
    return (fs::path(data) / "pitwall" / "standings.db").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (fs::path(home) / ".local" / "share" / "pitwall" / "standings.db").string();
  return {};
}

int pointsFor(const std::string& kind, std::optional<int> position, bool finished) {
  if (kind != "race" && kind != "heat" && kind != "final") return 0;
  return position ? league::pointsFor(*position, finished) : 0;
}

std::string Database::sentence(int code, const std::string& doing) const {
  // (the message of the last call, unless a later one succeeded: then the code's own)
  const std::string sqlite =
      db_ && sqlite3_errcode(db_) != SQLITE_OK ? sqlite3_errmsg(db_) : sqlite3_errstr(code);
  const std::string other = " (or give another file with --db FILE)";
  switch (code & 0xff) {
    case SQLITE_NOTADB:
      return path_ + " is not a pitwall standings database (SQLite, " + doing + ": " + sqlite +
             "): move it away" + other;
    case SQLITE_CORRUPT:
      return path_ + " is damaged (SQLite, " + doing + ": " + sqlite +
             "): nothing was written to it; keep a copy, rescue what it holds with `sqlite3 " +
             path_ + " .recover`, and move it away" + other;
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return path_ + " is locked by another program (" +
             (waitMs_ > 0 ? "still busy after " + formatNumber(waitMs_ / 1000.0, 3) + " s"
                          : std::string("busy, not waited for again while racing")) +
             ", " + doing +
             "): close what holds it (another pitwall writing, an sqlite3 shell in a "
             "transaction) and try again";
    case SQLITE_READONLY:
      return path_ + " cannot be written (read-only; " + doing +
             "): make it and its folder writable (chmod u+w)" + other;
    case SQLITE_CANTOPEN:
      return path_ + " cannot be opened (" + sqlite + "; " + doing +
             "): its folder must exist and be writable" + other;
    case SQLITE_CONSTRAINT:
      return path_ + ": " + doing + ": its event has that race already (a race is kept once; " +
             sqlite + ")";
    case SQLITE_FULL:
      return path_ + ": the disk is full (" + doing + "): free some space and try again";
    default:
      return path_ + ": " + sqlite + " (" + doing + ")";
  }
}

Result<std::unique_ptr<Database>, std::string> Database::open(const std::string& path,
                                                              bool create) {
  if (path.empty())
    return Unexpected{std::string(
        "no standings database: neither --db FILE, PITWALL_DB, XDG_DATA_HOME nor HOME is set")};
  std::error_code ec;
  if (!create && !fs::exists(path, ec))
    return Unexpected{"no standings at " + path +
                      " yet: a race or a league writes them (or give another file with --db FILE)"};
  if (fs::is_directory(path, ec))
    return Unexpected{path + " is a folder: the standings are a file (--db FILE)"};
  if (create) {
    const fs::path folder = fs::absolute(path, ec).parent_path();
    if (!fs::is_directory(folder, ec) && !fs::create_directories(folder, ec) && ec)
      return Unexpected{path + ": cannot make its folder " + folder.string() + ": " + ec.message() +
                        " (or give another file with --db FILE)"};
  }
  sqlite3* raw = nullptr;
  const int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0) | SQLITE_OPEN_NOMUTEX;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, flags, nullptr);
  std::unique_ptr<Database> db(new Database(raw, path));
  if (rc != SQLITE_OK) return Unexpected{db->sentence(rc, "opening it")};
  db->waitForLocks(true);
  sqlite3_extended_result_codes(raw, 0);
  if (create && sqlite3_db_readonly(raw, "main") == 1)
    return Unexpected{db->sentence(SQLITE_READONLY, "opening it to write")};
  // Whole? (a damaged page is found now, not in the middle of a league)
  {
    Statement check(raw, "PRAGMA quick_check(1)");
    if (check.prepared() != SQLITE_OK)
      return Unexpected{db->sentence(check.prepared(), "reading it")};
    const int step = check.step();
    if (step != SQLITE_ROW) return Unexpected{db->sentence(step, "checking it")};
    if (check.text(0) != "ok")
      return Unexpected{db->sentence(SQLITE_CORRUPT, "checking it: " + check.text(0))};
  }
  if (auto migrated = db->migrate(); !migrated) return Unexpected{migrated.error()};
  if (create) {
    if (auto written = db->probeWrite(); !written) return Unexpected{written.error()};
  }
  sqlite3_exec(raw, "PRAGMA foreign_keys = ON", nullptr, nullptr, nullptr);
  return db;
}

Database::~Database() {
  sqlite3_close(db_);
}

void Database::waitForLocks(bool wait) {
  waitForLocks(wait ? busyMs() : 0);
}

void Database::waitForLocks(int ms) {
  waitMs_ = std::max(0, ms);
  sqlite3_busy_timeout(db_, waitMs_);
}

Result<bool, std::string> Database::migrate() {
  auto version = [&]() -> Result<int, std::string> {
    Statement s(db_, "PRAGMA user_version");
    if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading it")};
    if (int rc = s.step(); rc != SQLITE_ROW) return Unexpected{sentence(rc, "reading it")};
    return s.integer(0);
  };
  auto v = version();
  if (!v) return Unexpected{v.error()};
  found_ = *v;
  if (found_ < 0)
    return Unexpected{path_ + " has schema version " + std::to_string(found_) +
                      ", which no pitwall writes: not a standings database of ours; move it away, "
                      "or give another file with --db FILE"};
  if (found_ > kSchemaVersion)
    return Unexpected{path_ + " has schema version " + std::to_string(found_) +
                      ", newer than this pitwall's " + std::to_string(kSchemaVersion) +
                      ": a newer pitwall wrote it; upgrade pitwall (nothing was changed), or give "
                      "another file with --db FILE"};
  if (found_ == kSchemaVersion) return checkTables();
  if (found_ == 0) {  // new — or another program's SQLite file
    Statement s(db_, "SELECT group_concat(name, ', ') FROM sqlite_master WHERE type = 'table'");
    if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading it")};
    if (int rc = s.step(); rc != SQLITE_ROW) return Unexpected{sentence(rc, "reading it")};
    if (!s.null(0))
      return Unexpected{
          path_ + " is an SQLite database, but not pitwall's standings (its tables: " + s.text(0) +
          "): move it away, or give another file with --db FILE"};
  }
  // One step at a time, each in a transaction of its own: a run killed between two steps leaves a
  // file at a version, never between two. Another pitwall migrating at once waits for the lock
  // and then finds the work done.
  for (;;) {
    if (int rc = sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr); rc != SQLITE_OK)
      return Unexpected{
          sentence(rc, "migrating it to schema version " + std::to_string(kSchemaVersion))};
    auto now = version();
    if (!now || *now >= kSchemaVersion) {
      sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr);
      if (!now) return Unexpected{now.error()};
      return checkTables();
    }
    const std::string step = std::string(kMigrations[static_cast<std::size_t>(*now)]) +
                             "; PRAGMA user_version = " + std::to_string(*now + 1) + ";";
    int rc = sqlite3_exec(db_, step.c_str(), nullptr, nullptr, nullptr);
    if (rc == SQLITE_OK) rc = sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) {
      const std::string why =
          sentence(rc, "migrating it from schema version " + std::to_string(*now) + " to " +
                           std::to_string(*now + 1));
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      return Unexpected{why};
    }
  }
}

// The tables of the current schema are there (a user may have dropped one: every write would fail
// with a sentence of SQLite's that says nothing).
Result<bool, std::string> Database::checkTables() {
  Statement s(db_, "SELECT name FROM sqlite_master WHERE type = 'table'");
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading it")};
  std::set<std::string> have;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW) have.insert(s.text(0));
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading it")};
  for (const char* table : {"events", "races", "results", "laps", "best_laps"})
    if (!have.count(table))
      return Unexpected{path_ + " has schema version " + std::to_string(kSchemaVersion) +
                        " but no table " + table +
                        " (removed by hand?): restore a copy, or give another file with --db FILE"};
  return true;
}

// Can the file be written? SQLite writes a journal beside it: a folder that takes no new file
// makes every write fail, so it is tried now (in a transaction rolled back), before a race.
Result<bool, std::string> Database::probeWrite() {
  // (the schema version written again as it is: a write that touches nothing of the user's)
  const std::string probe =
      "BEGIN IMMEDIATE; PRAGMA user_version = " + std::to_string(kSchemaVersion) + "; ROLLBACK;";
  int rc = sqlite3_exec(db_, probe.c_str(), nullptr, nullptr, nullptr);
  if (rc == SQLITE_OK) return true;
  // Locked by another program now: it can be written, later (the races are held meanwhile)
  if ((rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    return true;
  }
  const std::string why = sentence(rc, "trying a write");
  sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  return Unexpected{why};
}

Result<bool, std::string> Database::hasRace(std::int64_t event, const std::string& kind,
                                            int number) {
  Statement s(db_, "SELECT 1 FROM races WHERE event = ? AND kind = ? AND number = ?");
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading it")};
  s.bind(1, event);
  s.bind(2, kind);
  s.bind(3, number);
  const int rc = s.step();
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  return Unexpected{sentence(rc, "reading it")};
}

Result<std::int64_t, std::string> Database::beginEvent(const Event& e) {
  Statement s(db_,
              "INSERT INTO events(kind, title, track, started, details) "
              "VALUES(?, ?, ?, strftime('%Y-%m-%dT%H:%M:%SZ', 'now'), ?)");
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "adding an event")};
  s.bind(1, e.kind);
  s.bind(2, e.title);
  s.bind(3, e.track);
  s.bind(4, e.details);
  if (int rc = s.step(); rc != SQLITE_DONE) return Unexpected{sentence(rc, "adding an event")};
  return static_cast<std::int64_t>(sqlite3_last_insert_rowid(db_));
}

Result<bool, std::string> Database::addRace(std::int64_t event, const Race& race) {
  const std::string doing = "writing " + race.kind + " " + std::to_string(race.number);
  if (int rc = sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr); rc != SQLITE_OK)
    return Unexpected{sentence(rc, doing)};
  auto fail = [&](int rc) -> Result<bool, std::string> {
    const std::string why = sentence(rc, doing);
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    return Unexpected{why};
  };
  {
    Statement r(db_,
                "INSERT INTO races(event, kind, number, track, laps, ended) "
                "VALUES(?, ?, ?, ?, ?, strftime('%Y-%m-%dT%H:%M:%SZ', 'now'))");
    if (int rc = r.prepared(); rc != SQLITE_OK) return fail(rc);
    r.bind(1, event);
    r.bind(2, race.kind);
    r.bind(3, race.number);
    r.bind(4, race.track);
    r.bind(5, race.laps);
    if (int rc = r.step(); rc != SQLITE_DONE) return fail(rc);
  }
  const std::int64_t id = sqlite3_last_insert_rowid(db_);
  Statement e(db_,
              "INSERT INTO results(race, number, driver, car, position, finished, status, laps, "
              "best_lap, total_time, points, reason, file) "
              "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  Statement l(db_, "INSERT INTO laps(race, number, lap, time) VALUES(?, ?, ?, ?)");
  if (int rc = e.prepared(); rc != SQLITE_OK) return fail(rc);
  if (int rc = l.prepared(); rc != SQLITE_OK) return fail(rc);
  for (const Entry& x : race.entries) {
    e.reset();
    e.bind(1, id);
    e.bind(2, x.number);
    e.bind(3, x.driver);
    e.bind(4, x.car);
    e.bind(5, x.position);
    e.bind(6, x.finished ? 1 : 0);
    e.bind(7, x.status);
    e.bind(8, x.laps);
    e.bind(9, x.bestLap);
    e.bind(10, x.totalTime);
    e.bind(11, pointsFor(race.kind, x.position, x.finished));
    e.bind(12, x.reason);
    e.bind(13, x.file);
    if (int rc = e.step(); rc != SQLITE_DONE) return fail(rc);
    for (std::size_t k = 0; k < x.lapTimes.size(); ++k) {
      l.reset();
      l.bind(1, id);
      l.bind(2, x.number);
      l.bind(3, static_cast<int>(k + 1));
      l.bind(4, x.lapTimes[k]);
      if (int rc = l.step(); rc != SQLITE_DONE) return fail(rc);
    }
  }
  // Each entry's traced best lap becomes its driver's personal best in that car on this layout
  // when it beats the one kept (or none is).
  Statement b(
      db_,
      "INSERT INTO best_laps(driver, car, layout, track, lap, trace, event, set_at) "
      "VALUES(?, ?, ?, ?, ?, ?, ?, strftime('%Y-%m-%dT%H:%M:%SZ', 'now')) "
      "ON CONFLICT(driver, car, layout) DO UPDATE SET track = excluded.track, "
      "lap = excluded.lap, trace = excluded.trace, event = excluded.event, "
      "set_at = excluded.set_at WHERE excluded.lap < best_laps.lap "
      // (a kept lap that is not whole — edited, damaged — gives way to any new one)
      "OR NOT json_valid(best_laps.trace) "
      "OR coalesce(abs(json_extract(best_laps.trace, '$.time') - best_laps.lap) > 0.001, 1)");
  if (int rc = b.prepared(); rc != SQLITE_OK) return fail(rc);
  for (const Entry& x : race.entries) {
    if (!x.bestTrace || race.layout.empty()) continue;
    b.reset();
    b.bind(1, x.driver);
    b.bind(2, x.car);
    b.bind(3, race.layout);
    b.bind(4, race.track);
    b.bind(5, x.bestTrace->time);
    b.bind(6, x.bestTrace->json);
    b.bind(7, event);
    if (int rc = b.step(); rc != SQLITE_DONE) return fail(rc);
  }
  if (int rc = sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr); rc != SQLITE_OK)
    return fail(rc);
  return true;
}

Result<std::vector<KeptLap>, std::string> Database::bestLaps(const std::string& layout,
                                                             const std::string& who, int most) {
  Statement s(db_,
              "SELECT driver, car, track, lap, trace, set_at FROM best_laps "
              "WHERE layout = ? AND (? = '' OR driver = ? OR car = ?) "
              "ORDER BY lap, set_at LIMIT ?");
  if (int rc = s.prepared(); rc != SQLITE_OK)
    return Unexpected{sentence(rc, "reading the personal bests")};
  s.bind(1, layout);
  s.bind(2, who);
  s.bind(3, who);
  s.bind(4, who);
  s.bind(5, most);
  std::vector<KeptLap> out;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW) {
    KeptLap k;
    k.driver = s.text(0);
    k.car = s.text(1);
    k.track = s.text(2);
    k.lap = s.real(3).value_or(0);
    k.trace = s.text(4);
    k.when = s.text(5);
    out.push_back(std::move(k));
  }
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading the personal bests")};
  return out;
}

Result<bool, std::string> Database::endEvent(std::int64_t event) {
  Statement s(db_, "UPDATE events SET ended = strftime('%Y-%m-%dT%H:%M:%SZ', 'now') WHERE id = ?");
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "ending an event")};
  s.bind(1, event);
  if (int rc = s.step(); rc != SQLITE_DONE) return Unexpected{sentence(rc, "ending an event")};
  return true;
}

Result<std::vector<TableRow>, std::string> Database::table(const Filter& f) {
  bool any = false;
  const std::string sql =
      "SELECT r.driver, SUM(r.points), "
      "SUM(ra.kind IN ('race', 'heat', 'final')), "
      "SUM(ra.kind IN ('race', 'heat', 'final') AND r.finished AND r.position = 1), "
      "SUM(ra.kind IN ('race', 'heat', 'final') AND r.finished AND r.position <= 3), "
      "SUM(ra.kind IN ('race', 'heat', 'final') AND r.finished), MIN(r.best_lap) "
      "FROM results r JOIN races ra ON ra.id = r.race" +
      where(f, any) +
      " GROUP BY r.driver ORDER BY SUM(r.points) DESC, 4 DESC, 5 DESC, "
      "MIN(r.best_lap) IS NULL, MIN(r.best_lap), r.driver";
  Statement s(db_, sql.c_str());
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading the table")};
  bindFilter(s.raw(), f);
  std::vector<TableRow> rows;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW)
    rows.push_back({s.text(0), s.integer(1), s.integer(2), s.integer(3), s.integer(4), s.integer(5),
                    s.real(6)});
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading the table")};
  return rows;
}

Result<std::vector<Best>, std::string> Database::bests(const Filter& f) {
  bool any = true;  // (the WHERE below is there already)
  // SQLite takes a bare column's values from the row where MIN() found its value.
  const std::string sql =
      "SELECT r.driver, ra.track, MIN(r.best_lap), r.car, ra.ended, e.title "
      "FROM results r JOIN races ra ON ra.id = r.race JOIN events e ON e.id = ra.event "
      "WHERE r.best_lap IS NOT NULL" +
      where(f, any) + " GROUP BY r.driver, ra.track ORDER BY ra.track, MIN(r.best_lap), r.driver";
  Statement s(db_, sql.c_str());
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading the bests")};
  bindFilter(s.raw(), f);
  std::vector<Best> rows;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW)
    rows.push_back({s.text(0), s.text(1), s.text(3), s.text(4), s.text(5), s.real(2).value_or(0)});
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading the bests")};
  return rows;
}

Result<std::vector<Past>, std::string> Database::history(const std::string& driver) {
  Statement s(db_,
              "SELECT ra.ended, e.title, ra.kind, ra.track, r.car, r.status, ra.number, r.points, "
              "r.position, r.best_lap FROM results r JOIN races ra ON ra.id = r.race "
              "JOIN events e ON e.id = ra.event WHERE r.driver = ? ORDER BY ra.id");
  if (int rc = s.prepared(); rc != SQLITE_OK)
    return Unexpected{sentence(rc, "reading " + driver + "'s races")};
  s.bind(1, driver);
  std::vector<Past> rows;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW)
    rows.push_back({s.text(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.integer(6),
                    s.integer(7), s.optionalInt(8), s.real(9)});
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading " + driver + "'s races")};
  return rows;
}

Result<std::vector<EventInfo>, std::string> Database::events() {
  Statement s(db_,
              "SELECT e.id, e.kind, e.title, COALESCE(NULLIF(e.track, ''), (SELECT "
              "group_concat(DISTINCT ra.track) FROM races ra WHERE ra.event = e.id), ''), "
              "e.started, e.ended, "
              "(SELECT COUNT(*) FROM races ra WHERE ra.event = e.id), e.details FROM events e "
              "ORDER BY e.id");
  if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading the events")};
  std::vector<EventInfo> rows;
  int rc;
  while ((rc = s.step()) == SQLITE_ROW)
    rows.push_back({s.integer64(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5),
                    s.integer(6), s.text(7)});
  if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading the events")};
  return rows;
}

Result<StoredLeague, std::string> Database::league(std::optional<std::int64_t> id) {
  StoredLeague out;
  {
    Statement s(db_, id ? "SELECT id, title, track, started, ended, details FROM events "
                          "WHERE id = ? AND kind = 'league'"
                        : "SELECT id, title, track, started, ended, details FROM events "
                          "WHERE kind = 'league' AND ended IS NOT NULL ORDER BY id DESC LIMIT 1");
    if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading a league")};
    if (id) s.bind(1, *id);
    int rc = s.step();
    if (rc == SQLITE_DONE)
      return Unexpected{id ? path_ + " has no league " + std::to_string(*id) +
                                 " (pitwall standings --events lists them)"
                           : path_ + " has no league that ended (pitwall league … --db " + path_ +
                                 " races one)"};
    if (rc != SQLITE_ROW) return Unexpected{sentence(rc, "reading a league")};
    out.event = {s.integer64(0), "league", s.text(1), s.text(2), s.text(3), s.text(4), 0, {}};
    out.details = s.text(5);
  }
  std::map<std::string, std::size_t> index;
  {
    Statement s(db_,
                "SELECT r.driver, r.file, r.best_lap, ra.kind, ra.number, r.position, r.finished "
                "FROM results r JOIN races ra ON ra.id = r.race WHERE ra.event = ? "
                "ORDER BY ra.kind = 'heat', ra.number, r.position");
    if (int rc = s.prepared(); rc != SQLITE_OK) return Unexpected{sentence(rc, "reading a league")};
    s.bind(1, out.event.id);
    int rc;
    std::map<int, std::size_t> heatAt;
    while ((rc = s.step()) == SQLITE_ROW) {
      const std::string name = s.text(0);
      auto it = index.find(name);
      if (it == index.end()) {
        it = index.emplace(name, out.drivers.size()).first;
        out.drivers.push_back({name, s.text(1), std::nullopt});
      }
      if (out.drivers[it->second].file.empty()) out.drivers[it->second].file = s.text(1);
      if (s.text(3) == "qualifying") {
        out.drivers[it->second].qualifying = s.real(2);
      } else if (s.text(3) == "heat") {
        const int number = s.integer(4);
        if (!heatAt.count(number)) {
          heatAt[number] = out.heats.size();
          out.heats.emplace_back();
        }
        out.heats[heatAt[number]].push_back(
            {name, s.optionalInt(5).value_or(0), s.integer(6) != 0, s.real(2)});
      }
    }
    if (rc != SQLITE_DONE) return Unexpected{sentence(rc, "reading a league")};
    out.event.races = static_cast<int>(out.heats.size());
  }
  std::sort(out.drivers.begin(), out.drivers.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  return out;
}

}  // namespace pitwall::standings
