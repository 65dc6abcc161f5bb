#include "engine/view/code_api.hpp"

#include <charconv>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace pitwall::view {

using nlohmann::json;

namespace {

constexpr auto kReplace = json::error_handler_t::replace;
constexpr int kMaxLaps = 50;
constexpr std::size_t kTraceSamples = 2000;  // a Test's trace sent to the page, at most

CodeReply answer(int status, const json& body) {
  return {status, "application/json", body.dump(-1, ' ', false, kReplace), {}};
}

CodeReply refuse(int status, const std::string& why) {
  return answer(status, {{"error", why}});
}

CodeReply refuse(const classroom::Refusal& r) {
  return refuse(r.status, r.why);
}

std::string bearer(const std::string& header) {
  constexpr std::string_view kScheme = "Bearer ";
  if (header.size() <= kScheme.size() || header.compare(0, kScheme.size(), kScheme) != 0) return {};
  return header.substr(kScheme.size());
}

// The request's body as a JSON object; nullopt, and `reply` answered, when it is not one.
std::optional<json> object(const CodeRequest& r, CodeApi::Reply& reply) {
  json j = json::parse(r.body, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    reply(refuse(400, "the request's body is not a JSON object (" + std::to_string(r.body.size()) +
                          " bytes): send {\"text\": …} or as "
                          "docs/classroom.md says"));
    return std::nullopt;
  }
  return j;
}

// A whole number field from 1 to `most`; nullopt when missing or another thing.
std::optional<int> number(const json& j, const char* key, int most) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number_integer()) return std::nullopt;
  auto v = it->get<long long>();
  if (v < 1 || v > most) return std::nullopt;
  return static_cast<int>(v);
}

const std::string* text(const json& j, const char* key) {
  auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get_ptr<const std::string*>() : nullptr;
}

// A save's or a test's driver text ({"text": "…"}); nullopt, and `reply` answered, without one.
std::optional<std::string> driverText(const CodeRequest& r, CodeApi::Reply& reply) {
  auto j = object(r, reply);
  if (!j) return std::nullopt;
  const std::string* t = text(*j, "text");
  if (!t) {
    reply(refuse(400, "give the driver's text as a string (\"text\": \"…\")"));
    return std::nullopt;
  }
  return *t;
}

json deskJson(const classroom::Desk& d, const classroom::Classroom& room) {
  json j = {{"car", d.car},         {"carName", d.carName},          {"student", d.student},
            {"version", d.version}, {"raceOn", d.driver != nullptr}, {"locked", room.locked()}};
  j["failure"] = d.driver ? d.driver->whyOut() : std::string();
  j["driving"] = d.driver ? d.driver->drivingVersion() : 0;
  return j;
}

// The sentence of a child's stderr: its last "pitwall try: …" line(s), the prefix dropped.
std::string sentenceOf(const std::string& err) {
  constexpr std::string_view kPrefix = "pitwall try: ";
  auto at = err.rfind(kPrefix);
  std::string s = at == std::string::npos ? err : err.substr(at + kPrefix.size());
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  if (s.size() > 4000) s = s.substr(0, 4000) + " …";
  return s;
}

}  // namespace

CodeApi::CodeApi(Loop& loop, classroom::Classroom& room, Pairing& pairing, ChildRuns& tests,
                 std::vector<std::string> tryCommand, ChildRuns& leagues,
                 std::vector<std::string> leagueCommand)
    : loop_(loop),
      room_(room),
      pairing_(pairing),
      tests_(tests),
      tryCommand_(std::move(tryCommand)),
      leagues_(leagues),
      leagueCommand_(std::move(leagueCommand)) {}

bool CodeApi::handles(const std::string& target) const {
  return target.starts_with("/api/code/");
}

void CodeApi::handle(const CodeRequest& r, Reply reply) {
  std::string path = r.target.substr(0, r.target.find('?'));
  const bool get = r.method == "GET" || r.method == "HEAD", post = r.method == "POST";
  if (path == "/api/code/desks" && get) {
    json desks = json::array();
    for (const auto& [car, d] : room_.desks())
      desks.push_back({{"car", car}, {"carName", d.carName}, {"taken", !d.token.empty()}});
    return reply(answer(
        200, {{"desks", desks}, {"codeNeeded", pairing_.required()}, {"locked", room_.locked()}}));
  }
  if (path == "/api/code/join" && post) {
    auto j = object(r, reply);
    if (!j) return;
    if (pairing_.required()) {
      const std::string* code = text(*j, "code");
      auto ok = pairing_.check(r.client, code ? *code : std::string(), loop_.seconds());
      if (!ok) return reply(refuse(403, ok.error()));
    }
    auto car = number(*j, "car", 1 << 20);
    if (!car) return reply(refuse(400, "give the car to take as a number (\"car\": 2)"));
    const std::string* name = text(*j, "name");
    auto token = room_.join(*car, name ? *name : std::string(), r.local ? std::string() : r.client);
    if (!token) return reply(refuse(token.error()));
    return reply(answer(200, {{"token", *token}, {"car", *car}}));
  }
  if (path == "/api/code/teacher" || path.starts_with("/api/code/teacher/")) {
    if (!room_.isTeacher(bearer(r.authorization)))
      return reply(refuse(403,
                          "the teacher's page needs the teacher's address, with its key, "
                          "as the terminal printed it"));
    if (path.starts_with("/api/code/teacher/league/") && get) {
      const std::string k = path.substr(std::string_view("/api/code/teacher/league/").size());
      int n = 0;
      auto [end, ec] = std::from_chars(k.data(), k.data() + k.size(), n);
      std::ifstream f;
      if (!k.empty() && ec == std::errc{} && end == k.data() + k.size() && n >= 1)
        f.open(room_.leagueFolder(n) / "report.html", std::ios::binary);
      if (!f.is_open() || !f)
        return reply(refuse(404, "there is no league report '" + k.substr(0, 40) + "'"));
      std::ostringstream html;
      html << f.rdbuf();
      return reply({200, "text/html; charset=utf-8", html.str(), {}});
    }
    if (path != "/api/code/teacher") return reply(refuse(404, "no such page of the teacher's"));
    if (get) return reply(answer(200, room_.status()));
    if (post) return teacher(r, reply);
    return reply(refuse(405, "GET or POST"));
  }
  // the student's own desk, by their credential: nothing else names it
  classroom::Desk* desk = room_.byToken(bearer(r.authorization));
  if (!desk)
    return reply(refuse(401,
                        "this page holds no desk (or the teacher freed it): join again "
                        "with the lesson's code and a free car"));
  if (path == "/api/code/me" && get) {
    auto file = room_.read(*desk);
    if (!file) return reply(refuse(file.error()));
    json j = deskJson(*desk, room_);
    j["text"] = *file;
    return reply(answer(200, j));
  }
  if (path == "/api/code/save" && post) {
    auto t = driverText(r, reply);
    if (!t) return;
    auto saved = room_.save(*desk, *t);
    if (!saved) return reply(refuse(saved.error()));
    json out = {{"version", saved->version},
                {"driving", saved->driving},
                {"raceOn", saved->raceOn},
                {"error", saved->error},
                {"line", saved->line}};
    return reply(answer(200, out));
  }
  if (path == "/api/code/test" && post) {
    auto t = driverText(r, reply);
    if (!t) return;
    return test(*desk, *t, std::move(reply));
  }
  if (path == "/api/code/history" && get) {
    json list = json::array();
    for (const auto& h : room_.history(*desk))
      list.push_back({{"version", h.version}, {"bytes", h.bytes}, {"age", h.age}});
    return reply(answer(200, {{"car", desk->car}, {"saves", list}}));
  }
  if (path.starts_with("/api/code/history/") && get) {
    const std::string k = path.substr(std::string_view("/api/code/history/").size());
    int v = 0;
    auto [end, ec] = std::from_chars(k.data(), k.data() + k.size(), v);
    if (k.empty() || ec != std::errc{} || end != k.data() + k.size())
      return reply(refuse(404, "a save is named by its number (/api/code/history/3), not '" +
                                   k.substr(0, 80) + "'"));
    auto body = room_.version(*desk, v);
    if (!body) return reply(refuse(body.error()));
    return reply({200, "text/x-lua; charset=utf-8", *body,
                  "car-" + std::to_string(desk->car) + "-save-" + std::to_string(v) + ".lua"});
  }
  return reply(refuse(404, "no " + r.method + " " + path.substr(0, 120) +
                               " on the code page (docs/classroom.md lists what it takes)"));
}

void CodeApi::test(classroom::Desk& desk, const std::string& t, Reply reply) {
  auto file = room_.prepareTest(desk, t);
  if (!file) return reply(refuse(file.error()));
  std::vector<std::string> argv = tryCommand_;
  argv.push_back(file->string());
  argv.push_back("--json");
  desk.testing = true;
  const bool queued = tests_.run(std::move(argv), [this, &desk, reply](ChildOutcome o) {
    desk.testing = false;
    json out;
    if (!o.failure.empty()) return reply(refuse(500, "the test did not start: " + o.failure));
    if (o.timedOut)
      return reply(refuse(504, "the test ran past " +
                                   std::to_string(tests_.limits().timeout.count() / 1000) +
                                   " s and was stopped: does the driver loop for ever?"));
    if (o.tooLong)
      return reply(refuse(413, "the test wrote more than " +
                                   std::to_string(tests_.limits().maxOutput >> 20) +
                                   " MiB and was stopped: does the driver print in a loop?"));
    if (o.signal != 0 && o.out.empty())
      return reply(refuse(500, "the test was ended by signal " + std::to_string(o.signal) + " (" +
                                   strsignal(o.signal) + "): test again"));
    json result = json::parse(o.out, nullptr, false);
    if (result.is_discarded() || !result.is_object()) {
      // it did not run (a file that does not load, a driver that fails at once): the sentence
      std::string why = sentenceOf(o.err);
      if (why.empty()) why = "the test ended with status " + std::to_string(o.status);
      out = {{"status", "error"}, {"reason", why}, {"line", classroom::Classroom::lineOf(why)}};
    } else {
      out = result;
      out.erase("file");
      std::string why = result.contains("reason") && result["reason"].is_string()
                            ? result["reason"].get<std::string>()
                            : std::string();
      out["line"] = classroom::Classroom::lineOf(why);
      // the trace, thinned to what a chart shows
      if (out.contains("trace") && out["trace"].is_array() && out["trace"].size() > kTraceSamples) {
        json thin = json::array();
        const std::size_t n = out["trace"].size(), step = (n + kTraceSamples - 1) / kTraceSamples;
        for (std::size_t i = 0; i < n; i += step) thin.push_back(out["trace"][i]);
        out["trace"] = std::move(thin);
      }
    }
    out["seconds"] = o.seconds;
    out["waited"] = o.waited;
    reply(answer(200, out));
  });
  if (!queued) {
    desk.testing = false;
    reply(refuse(503, std::to_string(tests_.queued()) +
                          " tests are waiting already: test again in a little while"));
  }
}

void CodeApi::teacher(const CodeRequest& r, Reply& reply) {
  auto j = object(r, reply);
  if (!j) return;
  const std::string* action = text(*j, "action");
  const std::string a = action ? *action : std::string();
  if (a == "lock" || a == "unlock") {
    room_.lock(a == "lock");
    return reply(answer(200, room_.status()));
  }
  if (a == "start") {
    auto laps = j->contains("laps") ? number(*j, "laps", kMaxLaps) : std::optional<int>(5);
    if (!laps)
      return reply(refuse(
          400, "a race of 1 to " + std::to_string(kMaxLaps) + " laps: give \"laps\" as a number"));
    room_.requestStart(*laps);
    return reply(answer(200, {{"started", *laps}}));
  }
  if (a == "league") {
    auto laps = j->contains("laps") ? number(*j, "laps", 20) : std::optional<int>(3);
    if (!laps)
      return reply(refuse(400, "a league's heats of 1 to 20 laps: give \"laps\" as a number"));
    return league(*laps, reply);
  }
  if (a == "assign") {  // the teacher gives a free desk to a student: their credential, in a link
    auto car = number(*j, "car", 1 << 20);
    const std::string* name = text(*j, "name");
    auto token = room_.join(car ? *car : 0, name ? *name : std::string());
    if (!token) return reply(refuse(token.error()));
    return reply(answer(200, {{"car", *car}, {"link", "/code#desk=" + *token}}));
  }
  if (a == "reset" || a == "free") {
    auto car = number(*j, "car", 1 << 20);
    if (!car || !room_.byCar(*car))
      return reply(refuse(404, "give a desk's car as a number (\"car\": 2)"));
    if (a == "free") {
      room_.free(*car);
      return reply(answer(200, room_.status()));
    }
    auto done = room_.reset(*car);
    if (!done) return reply(refuse(done.error()));
    return reply(answer(200, {{"said", *done}}));
  }
  reply(refuse(400,
               "the teacher's actions are lock, unlock, start, league, assign, reset and free; "
               "not '" +
                   a.substr(0, 40) + "'"));
}

// The teacher's league: `pitwall league` over a copy of every desk's driver, off the loop; the
// answer is its standings and the address of its report.
void CodeApi::league(int laps, Reply reply) {
  if (leagues_.running() > 0 || leagues_.queued() > 0)
    return reply(refuse(409, "a league is running: wait for its standings"));
  auto prepared = room_.prepareLeague();
  if (!prepared) return reply(refuse(prepared.error()));
  std::vector<std::string> argv = leagueCommand_;
  for (const auto& f : prepared->files) argv.push_back(f.string());
  const auto folder = prepared->folder;
  const int number = prepared->number;
  argv.push_back("--laps");
  argv.push_back(std::to_string(laps));
  argv.push_back("--results");
  argv.push_back((folder / "results.json").string());
  argv.push_back("--report");
  argv.push_back((folder / "report.html").string());
  const bool queued = leagues_.run(std::move(argv), [reply, folder, number](ChildOutcome o) {
    if (!o.failure.empty()) return reply(refuse(500, "the league did not start: " + o.failure));
    if (o.timedOut) return reply(refuse(504, "the league ran too long and was stopped"));
    std::ifstream f(folder / "results.json");
    json results = json::parse(f, nullptr, false);
    if (o.status != 0 || results.is_discarded() || !results.contains("standings")) {
      std::string why = o.err.substr(o.err.size() > 2000 ? o.err.size() - 2000 : 0);
      return reply(
          refuse(500, "the league failed (status " + std::to_string(o.status) + "): " + why));
    }
    json standings = json::array();
    for (const auto& row : results["standings"])
      standings.push_back({{"position", row.value("position", 0)},
                           {"driver", row.value("driver", "")},
                           {"points", row.value("points", 0)},
                           {"wins", row.value("wins", 0)},
                           {"bestLap", row.contains("bestLap") ? row["bestLap"] : json(nullptr)}});
    reply(answer(200, {{"league", number},
                       {"standings", standings},
                       {"report", "/api/code/teacher/league/" + std::to_string(number)},
                       {"seconds", o.seconds}}));
  });
  if (!queued) reply(refuse(409, "a league is running: wait for its standings"));
}

}  // namespace pitwall::view
