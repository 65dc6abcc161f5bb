#include "engine/cli/repl.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "bindings/interrupt.hpp"
#include "bindings/object_types.hpp"
#include "bindings/script_host.hpp"
#include "engine/cli/repl_chunk.hpp"
#include "engine/core/console.hpp"
#include "engine/core/log.hpp"
#include "engine/protocol/anki/advertisement.hpp"

namespace pitwall::cli {

namespace {

constexpr const char* kPrompt = "> ";
constexpr const char* kMorePrompt = ">> ";

int g_wakeFd = -1;                         // the write end of the running Repl's self-pipe
volatile sig_atomic_t g_chunkWaiting = 0;  // a typed chunk waits (pitwall.sleep)

// SIGINT: async-signal-safe only. Lua code running now (a typed chunk, a script's callback) is
// interrupted; with none running, the loop is told to cancel the line being typed. A typed
// chunk that waits is Ctrl-C's target even while a script's callback runs: the loop ends it.
void onInterruptSignal(int) {
  int saved = errno;
  bool toWaitingChunk = g_chunkWaiting && !interrupt::inConsole();
  if ((toWaitingChunk || !interrupt::requestFromSignal()) && g_wakeFd >= 0) {
    char byte = 1;
    ssize_t written = ::write(g_wakeFd, &byte, 1);  // a full pipe already says it
    (void)written;
  }
  errno = saved;
}

std::string_view trim(std::string_view s) {
  auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

// `:word …` is a command; `::label::` is Lua (a goto label).
bool isCommand(std::string_view text) {
  return !text.empty() && text[0] == ':' && !(text.size() > 1 && text[1] == ':');
}

std::string firstLine(const std::string& text) {
  return text.substr(0, text.find('\n'));
}

// The values of a chunk as tostring shows them, tab-separated: what prints when pitwall.repl is
// not there.
constexpr const char* kShowFallback =
    "local t = table.pack(...) for i = 1, t.n do t[i] = tostring(t[i]) end "
    "return table.concat(t, '\\t')";

// `cars` when pitwall.repl is not there: by number and by name.
constexpr const char* kBindCarsFallback =
    "local all = {} for n, car in ipairs(pitwall.cars()) do all[n] = car all[car.name] = car end "
    "cars = all";

constexpr const char* kHelp =
    "Lua, in the world of the cars:\n"
    "  =expr                    shows the value of expr (an expression alone does too: 1 + 2)\n"
    "  cars[1], cars.groundshock  the cars, by number and by name: cars[1]:setSpeed(600)\n"
    "  an unfinished chunk (function f() …) goes on at the >> prompt until it is complete\n"
    "  help(), help(x)          the API, one line each: help(cars[1]), help(pitwall),\n"
    "                           help(require \"pitwall.race\"), help(pitwall.after)\n"
    "  pitwall.sleep(2)         a chunk runs as a task: it may wait; the prompt returns after\n"
    "Commands (at the start of a chunk):\n"
    "  :cars    the cars: number, name, model, speed, piece, lane offset, connected\n"
    "  :help    this text\n"
    "  :quit    stop the cars and leave (also Ctrl-D at an empty prompt)\n"
    "Keys:\n"
    "  Tab          completes globals, fields, car methods and events (_names once _ is typed)\n"
    "  Up, Down     history; Ctrl-R searches it\n"
    "  Ctrl-C       interrupts the chunk (also one that waits) or callback running now; at the\n"
    "               prompt, drops the line\n"
    "  Ctrl-D       at an empty prompt: quit; at the >> prompt: drop the unfinished chunk\n"
    "Lines printed by scripts, events and the log appear above the prompt.\n";

}  // namespace

std::string replHistoryFile(const std::string& option) {
  if (!option.empty()) return option;
  if (const char* env = std::getenv("PITWALL_HISTORY"); env && *env) return env;
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.pitwall_history";
  return {};
}

Repl::Repl(Loop& loop, std::function<ScriptHost&()> world, Options options)
    : world_(std::move(world)),
      options_(std::move(options)),
      editor_(loop.io(), LineEditor::Options{options_.historyFile}),
      wake_(loop.io()) {
  editor_.onLine = [this](const std::string& text) { line(text); };
  editor_.onEnd = [this] { end(); };
  editor_.completer = [this](const std::string& word) { return complete(word); };
}

Repl::~Repl() {
  if (!started_) return;
  ::sigaction(SIGINT, &oldInt_, nullptr);
  if (editor_.interactive()) ::sigaction(SIGTSTP, &oldTstp_, nullptr);
  g_wakeFd = -1;
  g_chunkWaiting = 0;
  ::close(wakeWrite_);
  if (editor_.interactive()) {
    console::setWriter({});
    log::setSink(nullptr);
  }
  // editor_ goes last (a member): the terminal is restored after everything above.
}

void Repl::start() {
  if (started_) return;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0)
    throw std::runtime_error(std::string("cannot make the REPL's signal pipe: ") +
                             std::strerror(errno));
  started_ = true;
  wake_.assign(fds[0]);
  wakeWrite_ = fds[1];
  g_wakeFd = wakeWrite_;
  waitInterrupt();
  struct sigaction onInt {};
  onInt.sa_handler = onInterruptSignal;
  sigemptyset(&onInt.sa_mask);
  onInt.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &onInt, &oldInt_);
  if (editor_.interactive()) {
    // Ctrl-Z would suspend the engine with the cars still driving: it does nothing here.
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    ::sigaction(SIGTSTP, &ignore, &oldTstp_);
    console::setWriter([this](std::string_view text) { editor_.printAbove(text); });
    log::setSink([this](log::Level, std::string_view logLine) {
      std::string text(logLine);
      text += '\n';
      editor_.printAbove(text);
    });
  }
  bindCars(world_());
  editor_.setPrompt(kPrompt);
  editor_.start();
}

void Repl::print(std::string_view text) {
  editor_.printAbove(text);
}

void Repl::worldChanged() {
  moduleWarned_ = false;  // the new world loads pitwall.repl afresh
  print("-- the Lua world was reloaded: `cars` is bound in the new one\n");
  bindCars(world_());
  if (chunk_) {  // it waited in the old world, which is gone with its tasks
    chunk_.reset();
    g_chunkWaiting = 0;
    fail("the chunk that was waiting at the prompt ended with the old Lua world");
    carryOn();
  }
}

void Repl::waitInterrupt() {
  wake_.async_read_some(boost::asio::buffer(wakeBytes_),
                        [this](const boost::system::error_code& ec, std::size_t) {
                          if (ec) return;  // closed: the Repl is going away
                          cancel();
                          waitInterrupt();
                        });
}

void Repl::cancel() {
  if (chunk_) return interruptChunk();
  pending_.clear();
  editor_.setPrompt(kPrompt);
  editor_.cancelLine();
}

void Repl::quit() {
  if (quitting_) return;
  quitting_ = true;
  editor_.stop();
  if (onQuit) onQuit();
}

void Repl::fail(std::string_view message) {
  ++failures_;
  std::string text(message);
  if (text.empty() || text.back() != '\n') text += '\n';
  if (editor_.interactive()) {
    editor_.printAbove(text);
  } else {  // piped: the values on stdout, the errors on stderr
    std::fwrite(text.data(), 1, text.size(), stderr);
    std::fflush(stderr);
  }
}

void Repl::line(const std::string& text) {
  // Several lines at once (a bracketed paste, a multi-line entry from the history) go one by
  // one, as if typed: `=1` and `=2` pasted together show 1 and 2, and a pasted function still
  // becomes one chunk.
  std::size_t from = 0;
  for (std::size_t nl; !quitting_ && (nl = text.find('\n', from)) != std::string::npos;
       from = nl + 1)
    oneLine(text.substr(from, nl - from));
  if (!quitting_) oneLine(text.substr(from));
}

void Repl::oneLine(const std::string& text) {
  if (chunk_) return queued_.push_back(text);  // run once the waiting chunk has ended
  // os.exit, pitwall.stop(): the run is ending; what is typed from now on is not run.
  if (world_().isShutDown()) return;
  if (pending_.empty()) {
    std::string_view typed = trim(text);
    if (typed.empty()) return;
    if (isCommand(typed)) {
      editor_.addHistory(std::string(typed));
      command(typed);
      return;
    }
    pending_ = text;
  } else {
    pending_ += '\n';
    pending_ += text;
  }

  ScriptHost& host = world_();
  lua_State* L = host.state();
  int top = lua_gettop(L);
  Chunk chunk = compileChunk(L, pending_);
  if (chunk.status == ChunkStatus::Incomplete) {
    editor_.setPrompt(kMorePrompt);
    return;
  }
  std::string code = std::move(pending_);
  pending_.clear();
  editor_.setPrompt(kPrompt);
  editor_.addHistory(code);  // a multi-line chunk is one entry
  if (chunk.status == ChunkStatus::Invalid) return fail(chunk.error);
  setEnvironment(host);
  run(host, top);
}

// The compiled chunk on top of the stack gets the prompt's globals as its _ENV
// (pitwall.repl's environment: the world's globals, read and written through, and `help`,
// which scripts do not see). Without the module it keeps the world's.
void Repl::setEnvironment(ScriptHost& host) {
  lua_State* L = host.state();
  const int chunk = lua_gettop(L);
  if (!pushModuleFunction(host, "environment")) return;
  lua::pushObjectTypes(L);  // for help: which object a userdata is
  lua_pushinteger(L, editor_.columns());
  std::string error;
  if (!host.callInteractive(2, 1, error)) {
    print("help is not available: " + firstLine(error) + "\n");
  } else if (lua_istable(L, -1)) {
    lua_setupvalue(L, chunk, 1);  // a main chunk's one upvalue is _ENV
  }
  lua_settop(L, chunk);
}

// The compiled chunk is on top of the stack, above `top`. It runs as a task (the script's main
// chunk does too): one that waits pauses the prompt until it ends (finished).
void Repl::run(ScriptHost& host, int top) {
  lua_State* L = host.state();
  bindCars(host);  // cars that joined since the last chunk are there
  lua_State* co = host.tasks().spawnConsole(
      L, [this, &host](lua_State* thread, int nresults, const std::string& error) {
        finished(host, thread, nresults, error);
      });
  lua_settop(L, top);
  if (!co) return;  // it ended at once
  chunk_ = Waiting{&host, co};
  g_chunkWaiting = 1;
  editor_.pause();
}

// A chunk ended: its values are shown (`nresults` on top of `co`'s stack) or its error.
void Repl::finished(ScriptHost& host, lua_State* co, int nresults, const std::string& error) {
  lua_State* L = host.state();
  const int top = lua_gettop(L);
  if (!error.empty()) {
    if (!host.exitStatus()) fail(error);  // os.exit: the run is ending, and that is no failure
  } else if (nresults > 0) {
    if (!lua_checkstack(L, nresults + LUA_MINSTACK)) {
      fail("the chunk returned too many values to show (" + std::to_string(nresults) + ")");
    } else {
      lua_xmove(co, L, nresults);
      show(host, top, nresults);
    }
  }
  lua_settop(L, top);
  if (chunk_ && chunk_->thread == co) {  // it had waited: the prompt is paused
    chunk_.reset();
    g_chunkWaiting = 0;
    carryOn();
  }
}

// Ctrl-C while a chunk waits: it ends where it waited, and the prompt comes back.
void Repl::interruptChunk() {
  Waiting waiting = *chunk_;
  chunk_.reset();
  g_chunkWaiting = 0;
  std::string where = waiting.host->tasks().cancel(waiting.thread);
  fail(where.empty() ? std::string("interrupted") : where);
  if (editor_.interactive()) queued_.clear();  // the rest of a paste goes with it, as a line would
  carryOn();
}

// After a chunk that waited: the lines entered meanwhile, one by one as if typed now, then the
// end of input if it came, then the prompt again.
void Repl::carryOn() {
  while (!chunk_ && !quitting_ && !queued_.empty()) {
    std::string text = std::move(queued_.front());
    queued_.pop_front();
    oneLine(text);
  }
  if (chunk_ || quitting_) return;
  if (queuedEnd_) {
    queuedEnd_ = false;
    end();
    if (chunk_ || quitting_) return;
  }
  editor_.resume();
}

// The `count` values above `top`, shown by pitwall.repl (tostring without it).
void Repl::show(ScriptHost& host, int top, int count) {
  lua_State* L = host.state();
  if (!pushModuleFunction(host, "show")) luaL_loadstring(L, kShowFallback);
  lua_insert(L, top + 1);
  std::string error;
  if (!host.callInteractive(count, 1, error)) return fail(error);
  if (lua_type(L, -1) != LUA_TSTRING) return;  // nil: nothing to show
  size_t len = 0;
  const char* shown = lua_tolstring(L, -1, &len);
  std::string text(shown, len);
  text += '\n';
  print(text);
}

void Repl::end() {
  if (chunk_) {  // the end of piped input while a chunk waits: after it
    queuedEnd_ = true;
    return;
  }
  if (!pending_.empty()) {
    // As lua.c: an unfinished chunk at the end of input is the syntax error it has.
    ScriptHost& host = world_();
    int top = lua_gettop(host.state());
    Chunk chunk = compileChunk(host.state(), pending_);
    lua_settop(host.state(), top);
    pending_.clear();
    editor_.setPrompt(kPrompt);
    fail(chunk.error.empty() ? "the chunk is not finished" : chunk.error);
    if (!editor_.stopped()) return;  // Ctrl-D at `>> `: back to a fresh prompt
  }
  quit();
}

void Repl::command(std::string_view text) {
  auto space = text.find_first_of(" \t");
  std::string name(text.substr(0, space));
  bool extra = space != std::string_view::npos && !trim(text.substr(space)).empty();
  if (name != ":quit" && name != ":q" && name != ":help" && name != ":cars")
    return fail("unknown command " + name + " (the commands are :help, :cars and :quit)");
  if (extra) return fail(name + " takes no arguments");
  if (name == ":help")
    print(kHelp);
  else if (name == ":cars")
    listCars();
  else
    quit();
}

void Repl::listCars() {
  const auto& cars = world_().fleet().cars();
  if (cars.empty()) return print("no cars\n");
  std::size_t nameWidth = 4, modelWidth = 5;
  for (const AnkiCar* car : cars) {
    nameWidth = std::max(nameWidth, car->identity().name.size());
    modelWidth = std::max(modelWidth, anki::modelName(car->identity().model_id).size());
  }
  std::string text;
  char row[256];
  std::snprintf(row, sizeof row, "%3s  %-*s  %-*s  %6s  %5s  %7s  %s\n", "#",
                static_cast<int>(nameWidth), "name", static_cast<int>(modelWidth), "model", "speed",
                "piece", "offset", "connected");
  text += row;
  for (const AnkiCar* car : cars) {
    const CarIdentity& id = car->identity();
    const CarState& s = car->state();
    std::string piece = s.piece < 0 ? "-" : std::to_string(s.piece);
    std::snprintf(row, sizeof row, "%3d  %-*s  %-*s  %6d  %5s  %7.1f  %s\n", id.number,
                  static_cast<int>(nameWidth), id.name.c_str(), static_cast<int>(modelWidth),
                  anki::modelName(id.model_id).c_str(), s.speed_mm_s, piece.c_str(), s.offset_mm,
                  s.connected ? "yes" : "no");
    text += row;
  }
  print(text);
}

std::vector<std::string> Repl::complete(const std::string& word) {
  std::vector<std::string> words;
  ScriptHost& host = world_();
  lua_State* L = host.state();
  int top = lua_gettop(L);
  bindCars(host);
  if (!pushModuleFunction(host, "complete")) return words;
  lua_pushlstring(L, word.data(), word.size());
  std::string error;
  if (!host.callInteractive(1, 1, error)) {
    lua_settop(L, top);
    print("completion failed: " + error + "\n");
    return words;
  }
  if (lua_istable(L, -1)) {
    auto n = static_cast<lua_Integer>(lua_rawlen(L, -1));
    for (lua_Integer i = 1; i <= n; ++i) {
      if (lua_rawgeti(L, -1, i) == LUA_TSTRING) words.emplace_back(lua_tostring(L, -1));
      lua_pop(L, 1);
    }
  }
  lua_settop(L, top);
  return words;
}

// require("pitwall.repl")[name], pushed; false (nothing pushed, said once) when it is not there.
bool Repl::pushModuleFunction(ScriptHost& host, const char* name) {
  lua_State* L = host.state();
  int top = lua_gettop(L);
  lua_getglobal(L, "require");
  lua_pushliteral(L, "pitwall.repl");
  std::string error;
  bool loaded = host.callInteractive(1, 1, error);
  if (loaded && lua_istable(L, -1) && lua_getfield(L, -1, name) == LUA_TFUNCTION) {
    lua_remove(L, -2);
    return true;
  }
  lua_settop(L, top);
  if (!moduleWarned_) {
    moduleWarned_ = true;
    std::string why = loaded ? std::string("it has no function ") + name : firstLine(error);
    log::warn("repl", "the Lua module pitwall.repl cannot be used (" + why +
                          "): values print with tostring and Tab completes nothing");
  }
  return false;
}

void Repl::bindCars(ScriptHost& host) {
  lua_State* L = host.state();
  int top = lua_gettop(L);
  if (!pushModuleFunction(host, "bindCars")) luaL_loadstring(L, kBindCarsFallback);
  std::string error;
  if (!host.callInteractive(0, 0, error)) print("cannot bind `cars`: " + error + "\n");
  lua_settop(L, top);
}

}  // namespace pitwall::cli
