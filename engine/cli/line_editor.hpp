#pragma once
// The REPL's input line: GNU readline driven through its callback interface from the engine's one
// loop (stdin waited on by Asio, one `rl_callback_read_char` per byte ready; no second thread), so
// cars, timers and scripts keep running while the operator types. Output from them is printed
// above the prompt without garbling the line being typed (printAbove).
//
// When stdin or stdout is not a terminal there is no readline at all: lines are read plainly
// from stdin on the loop, with no prompt and no history (`echo '=1+1' | pitwall repl`).
//
// GNU readline is GPL-3: everything that touches it is in this file and line_editor.cpp, so
// swapping in libedit's readline layer stays a one-file change (docs/repl.md).
#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/signal_set.hpp>

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace pitwall::cli {

class LineEditor {
 public:
  struct Options {
    std::string historyFile;  // empty: no history file
    int historySize = 1000;   // entries kept, in memory and in the file
  };
  using Completer = std::function<std::vector<std::string>(const std::string& word)>;

  // Reads the history file (terminal only). Only one LineEditor may exist at a time: readline's
  // state is global.
  LineEditor(boost::asio::io_context& io, Options options);
  // Restores the terminal, leaves the cursor on a fresh line, trims the history file.
  ~LineEditor();
  LineEditor(const LineEditor&) = delete;
  LineEditor& operator=(const LineEditor&) = delete;

  // stdin and stdout are terminals: readline edits the line.
  bool interactive() const { return tty_; }

  // Each line entered, without its newline. A multi-line paste may deliver several lines in one.
  std::function<void(const std::string& line)> onLine;
  // End of input: Ctrl-D at an empty line, or the end of piped input (after which nothing more
  // is read). At a terminal reading goes on unless stop() is called.
  std::function<void()> onEnd;
  // Tab: given the line up to the cursor, that text completed in every way that fits
  // (`cars[1]:setSp` → `cars[1]:setSpeed`); readline replaces only the word under the cursor.
  Completer completer;

  // Shows the prompt and starts reading.
  void start();
  // Reads no more; the prompt goes away (quit).
  void stop();
  bool stopped() const { return stopped_; }
  // While a chunk typed at the prompt waits (pitwall.sleep): no prompt, nothing read (at a
  // terminal what is typed meanwhile stays in the terminal's buffer and is read after resume),
  // and printAbove prints plainly. Called from the line handler, or at any time on the loop.
  void pause();
  // The prompt again, and reading goes on.
  void resume();
  bool paused() const { return paused_; }
  // The terminal's width in columns; 0 when there is no terminal.
  int columns() const;
  void setPrompt(std::string prompt);

  // Text from elsewhere (events, log lines, a script's print): any number of lines, with or
  // without a final newline. At the prompt it appears above it, on lines of its own, and the
  // prompt and the half-typed line are drawn again below it.
  void printAbove(std::string_view text);
  // Ctrl-C at the prompt: drops the typed line, shows ^C and a fresh prompt.
  void cancelLine();
  // One entry (a multi-line chunk stays one entry); appended to the history file at once.
  void addHistory(const std::string& entry);

 private:
  void waitInput();
  void waitResize();
  void endOfInput();
  void readTerminal();
  void readPlain();
  void handleLine(char* line);
  void write(std::string_view text);
  bool inputReady() const;
  void trimHistoryFile();
  static void lineCallback(char* line);  // readline's line handler

  bool tty_;
  Options options_;
  boost::asio::posix::stream_descriptor input_;  // a dup of stdin: closing it leaves stdin open
  boost::asio::signal_set resize_;               // SIGWINCH, at a terminal
  std::string prompt_ = "> ";
  bool started_ = false;
  bool stopped_ = false;
  bool inHandler_ = false;   // a line is being handled: readline shows no prompt now
  bool paused_ = false;      // pause(): readline's handler is removed, nothing is read
  bool waiting_ = false;     // a wait for input is armed
  bool resized_ = false;     // the window changed size while paused
  bool atLineStart_ = true;  // what we printed last ended with a newline
  bool historyOk_ = false;   // the history file can be appended to
  bool historyAppended_ = false;
  std::string plain_;  // piped input not yet ending in a newline
};

}  // namespace pitwall::cli
