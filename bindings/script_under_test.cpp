// pitwall.sim.script / pitwall.sim.reload: a scenario test runs a script under test in Lua worlds
// of its own, as `pitwall run --watch` runs a script, and replaces it with new versions at given
// engine times (docs/testing.md "Hot reload in scenarios"). The scenario watches from outside:
// while the script under test runs it has the cars' events, and the scenario goes by the
// simulator's ground truth (pitwall.sim.truth).
#include <array>
#include <filesystem>
#include <memory>

#include "bindings/lua_args.hpp"
#include "bindings/lua_object.hpp"
#include "bindings/lua_options.hpp"
#include "bindings/pitwall_module.hpp"
#include "bindings/reloader.hpp"
#include "engine/core/log.hpp"

namespace pitwall {

using lua::LuaError;

namespace {

constexpr const char* kMetatable = "pitwall.script_under_test";

// The script under test of one scenario. Its reloader lives until the scenario's world closes;
// once the script stopped (or the scenario's world shut down) it is shut down as well.
struct UnderTest {
  ScriptHost* scenario = nullptr;
  std::unique_ptr<Reloader> reloader;
  bool started = false;
  bool finished = false;  // it called pitwall.stop() (or the scenario ended it)
  int refused = 0;        // versions refused (and a first version that did not start)
  std::string refusal;    // why the last one was
  std::vector<Loop::TimerId> pending;

  ~UnderTest() {  // the scenario's world closes
    for (auto id : pending) scenario->loop().cancel(id);
    if (reloader && !finished) reloader->shutDown();
    reloader.reset();
  }

  // The script is done: nothing of it runs again and its cars are stopped; then (on the loop,
  // not inside the call that stopped it) the scenario's own handlers get the cars' events again.
  void end() {
    if (!reloader || finished) return;
    finished = true;
    reloader->shutDown();
    scenario->fleet().stopAll();
    scenario->loop().post([this] {
      if (!reloader) return;
      reloader->host().detach();
      if (!scenario->isShutDown()) scenario->attach();
    });
  }
};

// The scenario world's script under test (one at a time; kept in its registry), or nullptr.
char kCurrentKey;
UnderTest* current(lua_State* L) {
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kCurrentKey);
  auto* ut = static_cast<UnderTest*>(lua_touserdata(L, -1));
  lua_pop(L, 1);
  return ut;
}
void setCurrent(lua_State* L, UnderTest* ut) {
  lua_pushlightuserdata(L, ut);
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kCurrentKey);
}

const lua::TypeSpec& underTestType();

// A path when it names a file, else source text.
bool isFile(const std::string& s) {
  std::error_code ec;
  return s.find('\n') == std::string::npos && std::filesystem::is_regular_file(s, ec);
}

Reloader::Source sourceOf(const std::string& text, const std::string& name) {
  return Reloader::Source{text, name};
}

int create(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  if (UnderTest* running = current(L); running && !running->finished)
    throw LuaError(
        "a script under test is already running in this scenario; replace it with "
        "pitwall.sim.reload(path_or_source [, at]), or start the next once it has finished");
  std::string what = lua::checkString(L, 1, "script under test (a path or source text)");
  std::string name = "script_under_test.lua";
  HostOptions options = host.options();
  options.test_mode = false;  // its errors are reported as in a run; the scenario checks them
  options.detached = false;
  options.results.clear();
  static constexpr std::array<const char*, 2> kOptions = {"results", "name"};
  lua::Options read(L, 2, "sim.script", kOptions, "results =, name =");
  options.results = read.string("results").value_or(options.results);
  name = read.string("name").value_or(name);
  UnderTest* ut = &lua::newBox<UnderTest>(L, underTestType());
  lua_pushvalue(L, -1);
  luaL_ref(L, LUA_REGISTRYINDEX);  // lives as long as the scenario's world
  ut->scenario = &host;
  setCurrent(L, ut);
  bool file = isFile(what);
  host.atShutDown([ut] { ut->end(); });
  // Started on the loop, not inside the scenario's call: one Lua world runs at a time.
  host.loop().post([ut, what, name, file, options = std::move(options)]() mutable {
    ScriptHost& scenario = *ut->scenario;
    if (scenario.isShutDown()) return;
    scenario.detach();  // the cars' events go to the script under test now
    ut->reloader = std::make_unique<Reloader>(scenario.loop(), scenario.fleet(), scenario.sim(),
                                              std::move(options));
    ut->reloader->keepRunningOnError(true);  // as with --watch: a fix can be loaded
    ut->reloader->onStopRequested = [ut] { ut->end(); };
    auto started = file ? ut->reloader->start(what) : ut->reloader->startSource({what, name});
    ut->started = true;
    if (!started) {
      ++ut->refused;
      ut->refusal = started.error();
      log::error("script", "the script under test did not start: " + started.error());
    }
  });
  return 1;
}

int reload(lua_State* L) {
  ScriptHost& host = ScriptHost::from(L);
  UnderTest* ut = current(L);
  if (!ut) throw LuaError("no script under test to reload: start one with pitwall.sim.script");
  std::string what = lua::checkString(L, 1, "new version (a path or source text)");
  double at = lua_isnoneornil(L, 2) ? -1 : lua::checkNumber(L, 2, "at (engine time, s)");
  if (!(at < 1e9))  // NaN too
    throw LuaError("sim.reload: at " + lua::show(at) +
                   " is not an engine time: give the seconds of the run at which the save comes "
                   "(pitwall.now() + delay), or nothing for at once");
  bool file = isFile(what);
  Duration delay{};
  if (at >= 0) {
    double now = host.loop().seconds();
    if (at > now) delay = fromSeconds(at - now);
  }
  Loop::TimerId id = host.loop().after(delay, [ut, what, file, &host]() {
    if (!ut->reloader || ut->finished || host.isShutDown()) return;
    std::string name = ut->reloader->script();
    auto done =
        file ? ut->reloader->reloadFile(what) : ut->reloader->reloadSource(sourceOf(what, name));
    if (!done) {
      ++ut->refused;
      ut->refusal = done.error();
      log::error("reload", "the new version was not started: " + done.error() +
                               "\n  the running version carries on");
    } else {
      log::info("reload", "version " + std::to_string(ut->reloader->stats().reloads + 1) +
                              " of the script under test took over");
    }
  });
  ut->pending.push_back(id);
  return 0;
}

// ---- state fields: one entry each ----
UnderTest& underTestAt(lua_State* L, int self) {
  return lua::check<UnderTest>(L, self, underTestType());
}
Reloader* reloaderAt(lua_State* L, int self) {
  return underTestAt(L, self).reloader.get();
}

const lua::Field kFields[] = {
    {"started", [](lua_State* L, int self) { lua_pushboolean(L, underTestAt(L, self).started); }},
    {"finished", [](lua_State* L, int self) { lua_pushboolean(L, underTestAt(L, self).finished); }},
    {"version",
     [](lua_State* L, int self) {
       Reloader* r = reloaderAt(L, self);
       lua_pushinteger(L, r ? r->stats().reloads + 1 : 0);
     }},
    {"reloads",
     [](lua_State* L, int self) {
       Reloader* r = reloaderAt(L, self);
       lua_pushinteger(L, r ? r->stats().reloads : 0);
     }},
    {"refused", [](lua_State* L, int self) { lua_pushinteger(L, underTestAt(L, self).refused); }},
    {"refusal",
     [](lua_State* L, int self) {
       const std::string& why = underTestAt(L, self).refusal;
       why.empty() ? lua_pushnil(L) : (void)lua_pushstring(L, why.c_str());
     }},
    {"died",
     [](lua_State* L, int self) {
       Reloader* r = reloaderAt(L, self);
       lua_pushboolean(L, r && r->host().mainFailed());
     }},
    {"errors",
     [](lua_State* L, int self) {
       Reloader* r = reloaderAt(L, self);
       lua_pushinteger(L, r ? r->host().errorCount() : 0);
     }},
};

const lua::TypeSpec& underTestType() {
  static const lua::TypeSpec type{
      .metatable = kMetatable,
      .name = "script under test",
      .fields = kFields,
      .strict = true,
      .gc = [](lua_State* L, int self) { lua::destroyBox<UnderTest>(L, self, underTestType()); },
  };
  return type;
}

}  // namespace

void openScriptUnderTest(lua_State* L) {
  lua::registerType(L, underTestType());
  // on pitwall.sim, which is on top of the stack
  lua_pushcfunction(L, lua::guarded<create>);
  lua_setfield(L, -2, "script");
  lua_pushcfunction(L, lua::guarded<reload>);
  lua_setfield(L, -2, "reload");
}

}  // namespace pitwall
