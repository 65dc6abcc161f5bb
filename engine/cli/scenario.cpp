#include "engine/cli/scenario.hpp"

#include <lua.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "engine/cli/session.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

namespace {

// "a_test.lua:5" → {"a_test.lua", 5}; {"", 0} when it is not a file and a line.
std::pair<std::string, int> splitLocation(std::string_view at) {
  auto last = at.rfind(':');
  if (last == std::string_view::npos || last == 0 || last + 1 >= at.size()) return {"", 0};
  int line = 0;
  for (char c : at.substr(last + 1)) {
    if (c < '0' || c > '9') return {"", 0};
    line = line * 10 + (c - '0');
    if (line > 100'000'000) return {"", 0};
  }
  return {std::string(at.substr(0, last)), line};
}

// A traceback frame "a_test.lua:5: in main chunk"; {"", 0} for "[C]: in ?" and the like.
std::pair<std::string, int> frameLocation(std::string_view frame) {
  auto in = frame.find(": in ");
  if (in == std::string_view::npos) return {"", 0};
  return splitLocation(frame.substr(0, in));
}

bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  auto ca = fs::weakly_canonical(a, ec);
  if (ec) return false;
  auto cb = fs::weakly_canonical(b, ec);
  return !ec && ca == cb;
}

// The message a failed expectation raised last (scripts/pitwall/test.lua), if any; `field`
// "_failedAt": the same with the file and line of the expectation in front.
std::string lastExpectation(lua_State* L, const char* field = "_failed") {
  std::string text;
  lua_getglobal(L, "package");
  if (lua_istable(L, -1) && lua_getfield(L, -1, "loaded") == LUA_TTABLE &&
      lua_getfield(L, -1, "pitwall.test") == LUA_TTABLE &&
      lua_getfield(L, -1, field) == LUA_TSTRING)
    text = lua_tostring(L, -1);
  lua_settop(L, 0);
  return text;
}

}  // namespace

void readFailure(const std::string& failure, const std::string& testFile, ScenarioResult& into) {
  constexpr std::string_view kTraceback = "\nstack traceback:";
  auto cut = failure.find(kTraceback);
  std::string head = failure.substr(0, cut);
  // The main chunk is the test itself: "error in main chunk: " says nothing there.
  constexpr std::string_view kMain = "error in main chunk: ";
  if (std::string_view(head).starts_with(kMain)) head.erase(0, kMain.size());
  into.message = head;
  into.traceback.clear();
  if (cut != std::string::npos) {
    std::string_view rest = std::string_view(failure).substr(cut + kTraceback.size());
    while (!rest.empty()) {
      auto nl = rest.find('\n');
      std::string_view frame = rest.substr(0, nl);
      while (!frame.empty() && (frame.front() == '\t' || frame.front() == ' '))
        frame.remove_prefix(1);
      if (!frame.empty()) into.traceback.emplace_back(frame);
      if (nl == std::string_view::npos) break;
      rest.remove_prefix(nl + 1);
    }
  }
  // The test's line: the innermost frame in its own file; else where the message says it is,
  // when that is the test's file.
  for (const auto& frame : into.traceback) {
    auto [file, line] = frameLocation(frame);
    if (line > 0 && sameFile(file, testFile)) {
      into.file = file;
      into.line = line;
      return;
    }
  }
  auto colon = head.find(": ");
  if (colon == std::string::npos) return;
  auto [file, line] = splitLocation(std::string_view(head).substr(0, colon));
  if (line > 0 && sameFile(file, testFile)) {
    into.file = file;
    into.line = line;
  }
}

ScenarioResult runScenario(const std::string& file, const ScenarioSettings& settings) {
  ScenarioResult out;
  out.seed = settings.seed;
  auto begin = std::chrono::steady_clock::now();
  auto track = sim::namedLayout("oval");
  Session session(ClockKind::Virtual, std::move(*track), settings.seed);
  HostOptions host;
  host.test_mode = true;
  host.seed = settings.seed;
  host.library_frames = settings.libraryFrames;
  host.budget = std::chrono::milliseconds(std::llround(settings.budget * 1000));
  host.memory_limit = static_cast<std::size_t>(settings.luaMemory) << 20;
  auto finishTiming = [&] {
    out.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  };
  try {
    session.startHost(host);
  } catch (const std::exception& e) {
    out.status = ScenarioResult::Status::Errored;
    out.message = e.what();
    finishTiming();
    return out;
  }
  Loop& loop = session.loop();
  bool timedOut = false;
  loop.after(fromSeconds(settings.timeout), [&] {
    timedOut = true;
    out.waiting = session.host().tasks().waiting();  // before the stop ends them
    out.stoppedAt = loop.seconds();
    session.finish();
  });
  auto started = session.host().startFile(file);
  if (!started) {
    out.status = ScenarioResult::Status::Errored;
    out.message = started.error();
    finishTiming();
    return out;
  }
  loop.run();  // ends through Session::finish, which every way out of a run calls
  out.simulated = loop.seconds();
  finishTiming();
  std::string expected = lastExpectation(session.host().state());
  if (auto& failure = session.host().failure()) {
    readFailure(*failure, file, out);
    bool expectation = !expected.empty() && std::string_view(out.message).ends_with(expected);
    out.status = expectation ? ScenarioResult::Status::Failed : ScenarioResult::Status::Errored;
  } else if (!expected.empty()) {
    // An expectation failed and its error was taken by the script (pitwall.onError, a pcall):
    // still a failure — a scenario that handles its own errors must not swallow its checks.
    readFailure(lastExpectation(session.host().state(), "_failedAt"), file, out);
    out.status = ScenarioResult::Status::Failed;
  } else if (auto exit = session.host().exitStatus()) {
    out.status = ScenarioResult::Status::Errored;
    out.message = "the scenario called os.exit(" + std::to_string(*exit) +
                  "): a scenario passes by returning from its main chunk and fails through expect "
                  "or error";
  } else if (timedOut && !session.host().mainFinished()) {
    out.status = ScenarioResult::Status::TimedOut;
    char text[160];
    std::snprintf(text, sizeof text,
                  "still running after %g s of virtual time (raise it with --timeout)",
                  settings.timeout);
    out.message = text;
    // The test's line: where its main chunk (else its oldest task) waits in its own file.
    for (const auto& w : out.waiting) {
      auto at = w.find(" waiting at ");
      if (at == std::string::npos) continue;
      std::string_view place = std::string_view(w).substr(at + 12);
      place = place.substr(0, place.find(" (in "));
      auto [where, line] = splitLocation(place);
      if (line > 0 && sameFile(where, file)) {
        out.file = where;
        out.line = line;
        break;
      }
    }
  } else {
    out.waiting.clear();
  }
  return out;
}

}  // namespace pitwall::cli
