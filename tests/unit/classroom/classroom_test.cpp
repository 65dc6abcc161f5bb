// The classroom of the code page (engine/classroom/classroom.hpp, docs/classroom.md): desks and
// their files, credentials, saves with their history and limits, the lock, a desk's driver
// reloaded by a save — and the line an engine's sentence names.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/classroom/classroom.hpp"
#include "engine/core/loop.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;
using namespace pitwall::classroom;
namespace fs = std::filesystem;
using testing::TempDir;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// A driver as a race drives it: a save loads when its text has no "broken" in it.
struct FakeDriver : DeskDriver {
  const Classroom* room = nullptr;
  int car = 0, version = 1;
  std::string out;
  bool trySave(std::string& why) override {
    const std::string text = slurp(room->driverFile(car));
    if (text.find("broken") != std::string::npos) {
      why = "its file does not load: /x/car-" + std::to_string(car) +
            "/driver.lua:3: unexpected symbol near 'broken'";
      return false;
    }
    ++version;
    out.clear();
    return true;
  }
  bool restart(std::string& why) override { return trySave(why); }
  int drivingVersion() const override { return version; }
  std::string whyOut() const override { return out; }
};

}  // namespace

TEST_CASE("classroom: desks, credentials, saves and their history, within the folder") {
  TempDir dir("pitwall-classroom");
  Loop loop(ClockKind::Virtual);
  Limits limits;
  limits.history = 3;
  Classroom room(loop, dir.path / "lesson", "-- starter\n", limits);
  REQUIRE(room.prepare());
  REQUIRE(room.addDesk(1, "groundshock"));
  REQUIRE(room.addDesk(2, "skull"));
  CHECK(slurp(room.driverFile(2)) == "-- starter\n");
  CHECK(room.driverFile(2) == dir.path / "lesson" / "car-2" / "driver.lua");

  SUBCASE("a credential of one's own, per desk; a taken desk is refused") {
    auto alice = room.join(1, "  Alice ");
    REQUIRE(alice);
    CHECK(alice->size() == 32);
    CHECK(room.byToken(*alice)->student == "Alice");
    auto bob = room.join(1, "Bob");
    REQUIRE_FALSE(bob);
    CHECK(bob.error().status == 409);
    CHECK(bob.error().why.find("taken by Alice") != std::string::npos);
    auto bob2 = room.join(2, "Bob");
    REQUIRE(bob2);
    CHECK(*bob2 != *alice);
    CHECK(room.byToken(*bob2)->car == 2);
    // nothing else opens a desk: a prefix, another case, an empty one, the teacher's key
    CHECK(room.byToken(alice->substr(0, 31)) == nullptr);
    CHECK(room.byToken("") == nullptr);
    CHECK(room.byToken(room.teacherToken()) == nullptr);
    CHECK_FALSE(room.isTeacher(*alice));
    CHECK(room.isTeacher(room.teacherToken()));
    // freed by the teacher: the credential stops working, the desk is free again
    CHECK(room.free(1));
    CHECK(room.byToken(*alice) == nullptr);
    CHECK(room.join(1, "Carol"));
  }

  SUBCASE("one desk a device; this machine and the teacher's gift are not counted") {
    CHECK(room.join(1, "Alice", "10.0.0.5"));
    auto second = room.join(2, "Alice again", "10.0.0.5");
    REQUIRE_FALSE(second);
    CHECK(second.error().status == 409);
    CHECK(second.error().why.find("holds car 1 already") != std::string::npos);
    CHECK(room.join(2, "Bob", "10.0.0.6"));
    CHECK(room.free(1));
    CHECK(room.join(1, "Alice", "10.0.0.5"));  // freed, the device may take one again
    Classroom more(loop, dir.path / "more", "", limits);
    REQUIRE(more.prepare());
    for (int car = 1; car <= 3; ++car) REQUIRE(more.addDesk(car, "c"));
    CHECK(more.join(1, "a"));  // (no device: this machine, the teacher's gift)
    CHECK(more.join(2, "b"));
    CHECK(more.join(3, "c"));
  }

  SUBCASE("names: empty, too long, control characters; desks that are none") {
    CHECK(room.join(1, "   ").error().status == 400);
    CHECK(room.join(1, std::string(41, 'x')).error().why.find("41 characters") !=
          std::string::npos);
    CHECK(room.join(1, std::string(40, 'x')));
    CHECK(room.join(2, "a\nb").error().why.find("control character") != std::string::npos);
    CHECK(room.join(2, "evil\xE2\x80\xAEgnp.exe").error().why.find("control character") !=
          std::string::npos);
    auto none = room.join(7, "Dan");
    CHECK(none.error().status == 404);
    CHECK(none.error().why.find("pick one of 1, 2") != std::string::npos);
  }

  SUBCASE("a save writes the driver file and a numbered history; the oldest go") {
    Desk& d = *room.byToken(*room.join(2, "Bob"));
    for (int k = 1; k <= 5; ++k) {
      auto saved = room.save(d, "-- save " + std::to_string(k) + "\n");
      REQUIRE(saved);
      CHECK(saved->version == k);
      CHECK_FALSE(saved->raceOn);  // no race drives it: the next one will
    }
    CHECK(slurp(room.driverFile(2)) == "-- save 5\n");
    auto h = room.history(d);
    REQUIRE(h.size() == 3);
    CHECK(h[0].version == 5);
    CHECK(h[2].version == 3);
    CHECK(*room.version(d, 4) == "-- save 4\n");
    CHECK(room.version(d, 2).error().status == 404);  // dropped
    CHECK(room.version(d, 6).error().status == 404);
    CHECK(room.version(d, -1).error().status == 404);
    // nothing was written outside the desk's folder
    for (const auto& e : fs::recursive_directory_iterator(dir.path))
      CHECK(e.path().string().starts_with((dir.path / "lesson").string()));
    // a new lesson on the same folder goes on from the last number, the file kept
    Classroom again(loop, dir.path / "lesson", "-- starter\n", limits);
    REQUIRE(again.prepare());
    REQUIRE(again.addDesk(2, "skull"));
    CHECK(slurp(again.driverFile(2)) == "-- save 5\n");
    CHECK(again.byCar(2)->version == 5);
  }

  SUBCASE("limits: size, rate, the lock; a refused save writes nothing") {
    Desk& d = *room.byToken(*room.join(1, "Alice"));
    auto big = room.save(d, std::string(32 * 1024 + 1, '-'));
    CHECK(big.error().status == 413);
    CHECK(big.error().why.find("32.0 KiB") != std::string::npos);
    int saved = 0, refused = 0;
    for (int k = 0; k < 30; ++k) (room.save(d, "-- x\n") ? saved : refused)++;
    CHECK(saved == 10);  // the burst, then one every 2 s
    CHECK(refused == 20);
    loop.runAtMost(std::chrono::seconds(2));
    CHECK(room.save(d, "-- y\n"));
    room.lock(true);
    loop.runAtMost(std::chrono::seconds(10));
    auto locked = room.save(d, "-- z\n");
    CHECK(locked.error().status == 423);
    CHECK(slurp(room.driverFile(1)) == "-- y\n");
    room.lock(false);
    CHECK(room.save(d, "-- z\n"));
  }

  SUBCASE(
      "a race's driver: a good save drives, a broken one is said at its line and the old "
      "version drives on") {
    FakeDriver driver;
    driver.room = &room;
    driver.car = 1;
    room.attach(1, &driver);
    Desk& d = *room.byToken(*room.join(1, "Alice"));
    auto good = room.save(d, "-- good\n");
    REQUIRE(good);
    CHECK(good->raceOn);
    CHECK(good->driving);
    CHECK(driver.version == 2);
    auto bad = room.save(d, "-- a\n-- b\nbroken\n");
    REQUIRE(bad);               // saved (nothing lost) …
    CHECK_FALSE(bad->driving);  // … but not driving
    CHECK(bad->line == 3);
    CHECK(bad->error.find("unexpected symbol") != std::string::npos);
    CHECK(driver.version == 2);
    CHECK(room.status()["desks"][0]["lastError"] == bad->error);
    // the other desk's driver is not touched by it
    CHECK(room.byCar(2)->driver == nullptr);
    room.detach(1, &driver);
    CHECK(room.reset(1).error().status == 409);
  }

  SUBCASE(
      "a league: a copy of each desk's driver, named by car and student, in a folder of its own") {
    REQUIRE(room.join(1, "Ada Lovelace"));
    REQUIRE(room.join(2, "../../etc/x"));
    auto league = room.prepareLeague();
    REQUIRE(league);
    CHECK(league->number == 1);
    REQUIRE(league->files.size() == 2);
    CHECK(league->files[0] == dir.path / "lesson" / "leagues" / "1" / "car-1-adalovelace.lua");
    CHECK(league->files[1] == dir.path / "lesson" / "leagues" / "1" / "car-2-etcx.lua");
    CHECK(slurp(league->files[0]) == "-- starter\n");
    CHECK(room.prepareLeague()->number == 2);
  }

  SUBCASE("the teacher's start is taken once") {
    CHECK_FALSE(room.takeStart());
    room.requestStart(4);
    CHECK(room.takeStart() == 4);
    CHECK_FALSE(room.takeStart());
  }
}

TEST_CASE("classroom: the line an engine's sentence names in a desk's file") {
  CHECK(Classroom::lineOf("its file does not load: /a/car-2/driver.lua:4: unexpected symbol") == 4);
  CHECK(Classroom::lineOf("error in update of driver.lua of car 2: /a/driver.lua:12: boom") == 12);
  // the library's files are not the desk's
  CHECK(Classroom::lineOf("/usr/share/pitwall/scripts/pitwall/drivers.lua:120: bad") == 0);
  CHECK(Classroom::lineOf("driver.lua: no line") == 0);
  CHECK(Classroom::lineOf("driver.lua:99999999999999:") == 0);
  CHECK(Classroom::lineOf("") == 0);
}

TEST_CASE("classroom: a folder that cannot be used is a sentence") {
  TempDir dir("pitwall-classroom");
  Loop loop(ClockKind::Virtual);
  std::ofstream(dir.path / "file") << "x";
  Classroom room(loop, dir.path / "file" / "lesson", "", {});
  auto r = room.prepare();
  REQUIRE_FALSE(r);
  CHECK(r.error().find("cannot make the folder") != std::string::npos);
}
