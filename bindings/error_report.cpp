#include "bindings/error_report.hpp"

#include <cstdlib>

#include "bindings/car_binding.hpp"
#include "bindings/script_host.hpp"
#include "engine/core/log.hpp"

namespace pitwall {

ErrorReport::ErrorReport(ScriptHost& host) : host_(host), flood_(host.loop(), "script") {}

void ErrorReport::checkMemory() {
  if (!host_.memory().exceeded || memoryReported_) return;
  memoryReported_ = true;
  if (host_.ownBudget()) return host_.driverFailed(sandbox::memoryMessage(host_.memory()));
  std::string text = "error: " + sandbox::memoryMessage(host_.memory());
  if (host_.options().test_mode && !failure_) failure_ = text;
  log::error("script", text);
  host_.requestExit(EXIT_FAILURE);
}

void ErrorReport::report(const std::string& where, const std::string& message) {
  if (host_.exitStatus()) return;  // os.exit or the memory limit: the run is ending, and said why
  ++count_;
  // A driver world's first error puts its car out (the race director says why): no handler,
  // no log line of its own.
  if (host_.ownBudget()) {
    // Lua's own "not enough memory" (a refusal its emergency collection could not retry) is
    // the cap too: said as the cap.
    const bool capped = message == "not enough memory" && host_.memory().limit != 0;
    return host_.driverFailed("error in " + where + ": " +
                              (capped ? sandbox::memoryMessage(host_.memory()) : message));
  }
  // An error in a car's handler or listeners ("onPosition handler of car 1 (skull)") counts
  // towards stopping that car (CarBinding::handlerFailed), after the error itself is reported.
  struct CountAfter {
    ScriptHost& host;
    const std::string& where;
    const std::string& message;
    ~CountAfter() {
      if (host.cars_) host.cars_->handlerFailedIn(where, message);
    }
  } countAfter{host_, where, message};
  lua_State* L = host_.state();
  PITWALL_STACK_CHECK(L, 0, "an error's report (ErrorReport::report)");
  std::string text = "error in " + where + ": " + message;
  if (!inOnError_) {
    // A script may take its own errors (pitwall.onError): then they are handled, not failures.
    int top = lua_gettop(L);
    lua_getglobal(L, "pitwall");
    bool handler = lua_istable(L, -1) && lua_getfield(L, -1, "onError") == LUA_TFUNCTION;
    if (handler) {
      lua_remove(L, -2);
      lua_pushlstring(L, text.data(), text.size());
      lua_pushlstring(L, where.data(), where.size());
      inOnError_ = true;
      bool handled = host_.call(2, 0, "pitwall.onError");
      inOnError_ = false;
      if (handled) return;
    } else {
      lua_settop(L, top);
    }
  }
  if (host_.options().test_mode && !failure_) {
    failure_ = text;  // the test runner prints it with the scenario's result
    host_.requestStop();
    return;
  }
  if (flood_.admit(where, message)) log::error("script", text);
}

}  // namespace pitwall
