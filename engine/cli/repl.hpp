#pragma once
// The Lua prompt of `pitwall repl` (docs/repl.md): chunks typed at a LineEditor are compiled the
// way lua.c does it (repl_chunk.hpp) and run as tasks in the current Lua world, so they may
// wait (pitwall.sleep), with Ctrl-C able to interrupt them; their globals are the world's, and
// `help`; values are shown, words completed and help given by the Lua module `pitwall.repl`.
//
// While the prompt is up, everything printed for the operator (a script's print, io.write,
// pitwall.stdout, the log) goes above the prompt, and SIGINT is the REPL's: it interrupts the Lua
// code running at that moment, or, when none is, drops the line being typed. It never ends the
// program and never stops the cars.
#include <signal.h>

#include <lua.hpp>

#include <array>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/cli/line_editor.hpp"
#include "engine/core/loop.hpp"

namespace pitwall {
class ScriptHost;
}

namespace pitwall::cli {

// The REPL's history file: `option` (--history) when given, else $PITWALL_HISTORY, else
// ~/.pitwall_history; empty (no file) when there is no HOME either.
std::string replHistoryFile(const std::string& option);

class Repl {
 public:
  struct Options {
    std::string historyFile;  // empty: no history file
  };

  // `world` is asked for the Lua world for every chunk, completion and command, so a world
  // replaced by hot reload is used at once. Only one Repl may exist at a time.
  Repl(Loop& loop, std::function<ScriptHost&()> world, Options options);
  // Restores SIGINT, the log's sink and the console's writer, then the terminal.
  ~Repl();
  Repl(const Repl&) = delete;
  Repl& operator=(const Repl&) = delete;

  // Takes over SIGINT and the console, binds `cars`, shows the prompt.
  void start();
  // Ctrl-D at an empty prompt, `:quit`, or the end of piped input. The prompt is gone by then.
  std::function<void()> onQuit;
  // The Lua world was replaced (hot reload): says so above the prompt and binds `cars` in the
  // new one.
  void worldChanged();

  bool interactive() const { return editor_.interactive(); }
  // Text for the operator, above the prompt once it is up (a banner, a note).
  void print(std::string_view text);
  // Chunks and commands that failed (`pitwall repl` with piped input exits 1 when any did).
  int failures() const { return failures_; }

 private:
  void line(const std::string& text);
  void oneLine(const std::string& text);
  void end();
  void quit();
  void cancel();
  void fail(std::string_view message);
  void run(ScriptHost& host, int top);
  void setEnvironment(ScriptHost& host);
  void finished(ScriptHost& host, lua_State* co, int nresults, const std::string& error);
  void interruptChunk();
  void carryOn();
  void show(ScriptHost& host, int top, int count);
  void command(std::string_view text);
  void help();
  void listCars();
  std::vector<std::string> complete(const std::string& word);
  bool pushModuleFunction(ScriptHost& host, const char* name);
  void bindCars(ScriptHost& host);
  void waitInterrupt();

  std::function<ScriptHost&()> world_;
  Options options_;
  LineEditor editor_;
  std::string pending_;  // the lines of an unfinished chunk
  // A chunk that waits (pitwall.sleep): the prompt is paused until it ends, and what is
  // entered meanwhile (the rest of a paste, piped lines, the end of input) is kept for then.
  struct Waiting {
    ScriptHost* host;
    lua_State* thread;
  };
  std::optional<Waiting> chunk_;
  std::deque<std::string> queued_;
  bool queuedEnd_ = false;
  int failures_ = 0;
  bool started_ = false;
  bool quitting_ = false;
  bool moduleWarned_ = false;  // said once per world that pitwall.repl cannot be used
  // Ctrl-C with no Lua code running: the signal handler writes a byte, the loop cancels the line.
  int wakeWrite_ = -1;
  boost::asio::posix::stream_descriptor wake_;
  std::array<char, 16> wakeBytes_{};
  struct sigaction oldInt_ {};
  struct sigaction oldTstp_ {};
};

}  // namespace pitwall::cli
