#pragma once
// The code page's requests (docs/classroom.md "What the page asks"), for the view's server: JSON
// in, JSON out, each answered once — a Test when its `pitwall try` child has ended, off the loop.
//
//   GET  /api/code/desks              the desks (car, name, taken), whether a join code is needed
//   POST /api/code/join               {code, car, name} → {token, car}: the student's credential
//   GET  /api/code/me                 the student's desk, file, saves, driver, the lock
//   POST /api/code/save               {text} → {version, driving, raceOn, error, line}
//   POST /api/code/test               {text} → {status, laps, best, reason, line, trace, seconds}
//   GET  /api/code/history            the student's saves
//   GET  /api/code/history/K          save K's text (a download)
//   GET  /api/code/teacher            every desk (the teacher's credential)
//   POST /api/code/teacher            {action: lock | unlock | start (laps) | reset (car) |
//                                      free (car) | assign (car, name) | league (laps)}: an
//                                      assign answers with the student's link (/code#desk=…),
//                                      a league with its standings
//   GET  /api/code/teacher/league/K   league K's HTML report
//
// A student's requests carry "Authorization: Bearer TOKEN" (their desk's credential, from join);
// the teacher's carry the teacher's, which the terminal prints. Nothing else names a desk: a
// student reaches their own desk's file and driver and no other, whatever the request says.
// Every refusal is a status and {"error": sentence}.
#include <functional>
#include <string>

#include "engine/classroom/classroom.hpp"
#include "engine/core/child_runs.hpp"
#include "engine/view/pairing.hpp"

namespace pitwall::view {

struct CodeRequest {
  std::string method;         // "GET", "POST", …
  std::string target;         // "/api/code/save", with any query
  std::string body;           // what came (at most the server's limit)
  std::string authorization;  // the header's value
  std::string client;         // Pairing::clientKey of who sent it
  bool local = false;         // from this machine itself (not through a --view-host proxy)
};

struct CodeReply {
  int status = 200;
  std::string contentType = "application/json";
  std::string body;
  std::string filename;  // set: a download (Content-Disposition)
};

class CodeApi {
 public:
  using Reply = std::function<void(CodeReply)>;
  // `tryCommand`: the program and first arguments a Test runs (the pitwall binary and "try");
  // the file and "--json" follow. `leagueCommand` the same for the teacher's league ("league"),
  // run by `leagues`.
  CodeApi(Loop& loop, classroom::Classroom& room, Pairing& pairing, ChildRuns& tests,
          std::vector<std::string> tryCommand, ChildRuns& leagues,
          std::vector<std::string> leagueCommand);
  // True when the target is one of its own (/api/code/…); `reply` is called once, now or later.
  bool handles(const std::string& target) const;
  void handle(const CodeRequest& request, Reply reply);

 private:
  void test(classroom::Desk& desk, const std::string& text, Reply reply);
  void teacher(const CodeRequest& request, Reply& reply);
  void league(int laps, Reply reply);

  Loop& loop_;
  classroom::Classroom& room_;
  Pairing& pairing_;
  ChildRuns& tests_;
  std::vector<std::string> tryCommand_;
  ChildRuns& leagues_;
  std::vector<std::string> leagueCommand_;
};

}  // namespace pitwall::view
