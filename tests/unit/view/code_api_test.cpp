// The code page's requests (engine/view/code_api.hpp, docs/classroom.md) without a browser: the
// credential decides the desk, a Test runs off the loop in a child (here a stand-in for `pitwall
// try` that waits), one test at a time per desk, a full queue refused with a sentence, and the
// test's answer — its JSON, or the sentence of a file that does not load with its line.
#include <doctest/doctest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "engine/classroom/classroom.hpp"
#include "engine/core/child_runs.hpp"
#include "engine/core/loop.hpp"
#include "engine/view/code_api.hpp"
#include "engine/view/pairing.hpp"
#include "tests/support/temp_dir.hpp"

using namespace pitwall;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct Room {
  pitwall::testing::TempDir temp{"pitwall-code-api"};
  fs::path dir = temp.path / "lesson";
  Loop loop{ClockKind::Real};
  classroom::Classroom room;
  view::Pairing pairing{false, ""};
  ChildRuns runs, leagues;
  view::CodeApi api;
  // the stand-in for `pitwall try FILE --json`: reads the file's first line as what to do
  static std::vector<std::string> stand_in() {
    return {"/bin/sh", "-c",
            "sleep 0.3; case \"$(head -1 \"$0\")\" in "
            "*broken*) echo 'pitwall try: its file does not load: /x/test/driver.lua:2: boom' >&2; "
            "exit 1;; "
            "*killed*) kill -9 $$;; "
            "*) echo '{\"status\":\"finished\",\"laps\":[4.1,4.0],\"reason\":null}';; esac"};
  }
  explicit Room(int parallel = 2, std::size_t queue = 64)
      : room(loop, dir, "-- starter\n"),
        runs(loop, ChildLimits{.parallel = parallel, .queue = queue}),
        leagues(loop, ChildLimits{}),
        api(loop, room, pairing, runs, stand_in(), leagues, {"/bin/false"}) {
    REQUIRE(room.prepare());
    for (int car = 1; car <= 4; ++car) REQUIRE(room.addDesk(car, "car" + std::to_string(car)));
  }

  std::string join(int car) {
    std::optional<view::CodeReply> r;
    api.handle({"POST", "/api/code/join",
                json{{"car", car}, {"name", "s" + std::to_string(car)}}.dump(), "", "c", true},
               [&](view::CodeReply x) { r = x; });
    REQUIRE(r);
    REQUIRE(r->status == 200);
    return json::parse(r->body)["token"];
  }
  // Sends a request; the reply, once it came (at most 10 s of the loop)
  std::optional<view::CodeReply>* ask(const std::string& path, const json& body,
                                      const std::string& token) {
    auto* slot = new std::optional<view::CodeReply>();
    replies.emplace_back(slot);
    api.handle({"POST", path, body.dump(), "Bearer " + token, "c"},
               [slot](view::CodeReply x) { *slot = std::move(x); });
    return slot;
  }
  std::vector<std::unique_ptr<std::optional<view::CodeReply>>> replies;
};

}  // namespace

TEST_CASE("code api: a test runs off the loop; one at a time per desk; its answer") {
  Room r;
  const std::string a = r.join(1), b = r.join(2);
  auto* first = r.ask("/api/code/test", {{"text", "-- good\n"}}, a);
  auto* again = r.ask("/api/code/test", {{"text", "-- good\n"}}, a);  // the same desk at once
  auto* other = r.ask("/api/code/test", {{"text", "-- broken\n"}}, b);
  REQUIRE(*again);  // answered at once: refused
  CHECK((*again)->status == 409);
  CHECK(json::parse((*again)->body)["error"].get<std::string>().find("still running") !=
        std::string::npos);
  CHECK_FALSE(*first);  // waiting for its child: the loop goes on
  CHECK_FALSE(*other);
  REQUIRE(r.loop.runUntil([&] { return first->has_value() && other->has_value(); },
                          std::chrono::seconds(10)));
  json ok = json::parse((*first)->body);
  CHECK(ok["status"] == "finished");
  CHECK(ok["laps"].size() == 2);
  CHECK(ok["line"] == 0);
  CHECK(ok["seconds"].get<double>() >= 0.3);
  json bad = json::parse((*other)->body);
  CHECK(bad["status"] == "error");
  CHECK(bad["reason"] == "its file does not load: /x/test/driver.lua:2: boom");
  CHECK(bad["line"] == 2);
  // each desk's test read its own file
  CHECK(fs::exists(r.room.testFile(1)));
  CHECK(fs::exists(r.room.testFile(2)));
  // a test that dies by a signal is said so
  auto* killed = r.ask("/api/code/test", {{"text", "-- killed\n"}}, b);
  REQUIRE(r.loop.runUntil([&] { return killed->has_value(); }, std::chrono::seconds(10)));
  CHECK((*killed)->status == 500);
  CHECK(json::parse((*killed)->body)["error"].get<std::string>().find("signal 9") !=
        std::string::npos);
  // and once it answered, the desk may test again
  auto* later = r.ask("/api/code/test", {{"text", "-- good\n"}}, a);
  REQUIRE(r.loop.runUntil([&] { return later->has_value(); }, std::chrono::seconds(10)));
  CHECK((*later)->status == 200);
}

TEST_CASE("code api: thirty desks' tests queue; past the queue, a sentence") {
  Room r(1, 2);
  const std::string t1 = r.join(1), t2 = r.join(2), t3 = r.join(3), t4 = r.join(4);
  auto* a = r.ask("/api/code/test", {{"text", "-- good\n"}}, t1);  // runs
  auto* b = r.ask("/api/code/test", {{"text", "-- good\n"}}, t2);  // waits
  auto* c = r.ask("/api/code/test", {{"text", "-- good\n"}}, t3);  // waits
  auto* d = r.ask("/api/code/test", {{"text", "-- good\n"}}, t4);  // refused: the queue is full
  REQUIRE(*d);
  CHECK((*d)->status == 503);
  CHECK(json::parse((*d)->body)["error"].get<std::string>().find("tests are waiting") !=
        std::string::npos);
  REQUIRE(r.loop.runUntil([&] { return a->has_value() && b->has_value() && c->has_value(); },
                          std::chrono::seconds(10)));
  CHECK(json::parse((*c)->body)["waited"].get<double>() >= 0.5);  // behind two of 0.3 s
  // desk 4 was not left "testing" by its refusal
  auto* e = r.ask("/api/code/test", {{"text", "-- good\n"}}, t4);
  REQUIRE(r.loop.runUntil([&] { return e->has_value(); }, std::chrono::seconds(10)));
  CHECK((*e)->status == 200);
}
