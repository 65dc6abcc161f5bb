#pragma once
// The classroom of the view's code page (docs/classroom.md): a desk for each car of the run, a
// folder of files for each desk, the students who joined and their credentials, the teacher's.
//
//   FOLDER/car-N/driver.lua         the desk's driver: what the car races (pitwall.driverFiles)
//   FOLDER/car-N/history/K.lua      every save, K = 1, 2, … (the last kHistory kept)
//   FOLDER/car-N/test/driver.lua    what the last Test ran
//
// No path here comes from a request: a desk is a car's number, a version a number, and every
// file's name is made from them, so nothing a page sends can leave the folder. A student holds
// one desk through a credential of their own (a random token handed out when they join; the
// event's join code is not an identity), and reaches only that desk's files and driver. Saves
// are bounded in size and rate; the teacher can lock them.
//
// The driver a desk's file races in is the bindings' (a driver world): it attaches itself here
// while it drives (attach/detach), and a save reloads it through DeskDriver::trySave — the old
// version keeps driving when the new one does not load.
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "engine/core/loop.hpp"
#include "engine/core/result.hpp"
#include "engine/core/token_bucket.hpp"

namespace pitwall::classroom {

// A desk's driver while a race drives it (bindings/driver_world.hpp).
class DeskDriver {
 public:
  virtual ~DeskDriver() = default;
  // The file saved again: true when its new version drives now; else false and the sentence
  // (file and line), and the version driving goes on.
  virtual bool trySave(std::string& why) = 0;
  // The file loaded again as if new: an out driver comes back (the teacher's reset). False and
  // why when it does not load (the driver is out then).
  virtual bool restart(std::string& why) = 0;
  virtual int drivingVersion() const = 0;  // its world's version (1, 2, …)
  virtual std::string whyOut() const = 0;  // why it is out; empty when it drives
};

struct Limits {
  std::size_t maxFile = 32 * 1024;                 // a driver file's bytes
  RateLimit saves{.perSecond = 0.5, .burst = 10};  // a desk's saves
  RateLimit tests{.perSecond = 0.2, .burst = 3};   // a desk's tests
  std::size_t history = 100;                       // saves kept per desk
  std::size_t maxName = 40;                        // a student's name, in characters
};

// What a request may get back: an HTTP status and a sentence (what was wrong, the value, what
// to do).
struct Refusal {
  int status;
  std::string why;
};

struct Desk {
  int car = 0;
  std::string carName;
  std::string student;  // empty: free
  std::string token;    // the student's credential; empty: free
  std::string device;   // the client that joined it (empty: not counted)
  DeskDriver* driver = nullptr;
  int saves = 0;          // this run's saves
  int version = 0;        // the last history entry's number
  std::string lastError;  // the last save's or test's sentence, if it failed
  double lastSeen = -1;   // loop seconds of the student's last request
  TokenBucket saveBucket, testBucket;
  bool testing = false;
};

struct SaveResult {
  int version = 0;       // its history number
  bool driving = false;  // its new version drives the car now
  bool raceOn = false;   // a race drives the desk's car (else it drives from the next one)
  std::string error;     // the engine's sentence when it did not load
  int line = 0;          // the line the sentence names in the file, 0 when none
};

struct HistoryEntry {
  int version;
  std::size_t bytes;
  double age;  // seconds since it was saved
};

class Classroom {
 public:
  // `folder`: where the desks' folders go (made when missing); `starter`: the text a new desk's
  // driver starts as.
  Classroom(Loop& loop, std::filesystem::path folder, std::string starter, Limits limits = {});

  // Makes the folder, checks it can be written. The error names it and what to do.
  Result<bool, std::string> prepare();
  // A desk for each car (number, name): its folder made, its driver file the starter when there
  // is none (a file kept from an earlier lesson is kept). The error names the file.
  Result<bool, std::string> addDesk(int car, std::string name);
  // The driver file of a car's desk (absolute).
  std::filesystem::path driverFile(int car) const;
  std::filesystem::path testFile(int car) const;
  const std::filesystem::path& folder() const { return folder_; }

  const std::string& teacherToken() const { return teacher_; }
  bool isTeacher(std::string_view token) const;
  // The desk whose student holds `token`; nullptr for none.
  Desk* byToken(std::string_view token);
  Desk* byCar(int car);
  const std::map<int, Desk>& desks() const { return desks_; }

  // A student takes a free desk under a name: their new credential. Refused when the desk is
  // taken or is none, the name is empty, too long or has control characters — or `device` (the
  // client's key; empty: not counted — this machine, the teacher's gift) holds a desk already:
  // one desk a device, so one student cannot take the class's cars.
  Result<std::string, Refusal> join(int car, std::string_view name, std::string device = {});
  // The teacher frees a desk: its credential stops working (its files stay).
  bool free(int car);

  Result<std::string, Refusal> read(const Desk& d) const;
  Result<SaveResult, Refusal> save(Desk& d, std::string_view text);
  // A test's text, checked (size, rate, one at a time) and written where the test reads it.
  Result<std::filesystem::path, Refusal> prepareTest(Desk& d, std::string_view text);
  std::vector<HistoryEntry> history(const Desk& d) const;
  Result<std::string, Refusal> version(const Desk& d, int version) const;

  void lock(bool locked) { locked_ = locked; }
  bool locked() const { return locked_; }

  // The teacher's start: the laps of the race asked for, taken once by the race script
  // (pitwall.classroom.nextStart()).
  void requestStart(int laps) { start_ = laps; }
  std::optional<int> takeStart();
  // The teacher's league (`pitwall league` over the desks' drivers, off the loop): a new folder
  // FOLDER/leagues/K with a copy of each desk's driver named by its car and student
  // ("car-2-bob.lua", as the league names its drivers). The error names the folder.
  struct League {
    int number = 0;
    std::filesystem::path folder;
    std::vector<std::filesystem::path> files;
  };
  Result<League, Refusal> prepareLeague();
  std::filesystem::path leagueFolder(int number) const;
  // The teacher's reset of a desk's car: its driver loaded again from its file.
  Result<std::string, Refusal> reset(int car);

  // The desk's driver while a race drives it.
  void attach(int car, DeskDriver* driver);
  void detach(int car, DeskDriver* driver);

  // The desks as the teacher's page shows them (no credentials).
  nlohmann::json status() const;

  // The line a sentence names in a desk's driver file ("driver.lua:4: …"); 0 when none.
  static int lineOf(std::string_view sentence);

 private:
  Result<bool, Refusal> writeFile(const std::filesystem::path& path, std::string_view text) const;

  Loop& loop_;
  std::filesystem::path folder_;
  std::string starter_;
  Limits limits_;
  std::string teacher_;
  std::map<int, Desk> desks_;
  bool locked_ = false;
  std::optional<int> start_;
};

// kTokenBytes random bytes from the kernel's CSPRNG (getrandom), as hex.
std::string newToken();

}  // namespace pitwall::classroom
