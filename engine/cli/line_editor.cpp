#include "engine/cli/line_editor.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>

// readline's headers need stdio first.
#include <readline/history.h>
#include <readline/readline.h>

#include "engine/core/log.hpp"

namespace pitwall::cli {

namespace {

LineEditor* g_editor = nullptr;  // readline's callbacks are plain functions

// Lua's operators, separators and openers break words; `.`, `:`, `[` and `]` do not, so
// `cars[1]:setSp` and `cars.groundshock.spe` are each one word for the completer.
const char* const kWordBreaks = " \t\n\"'`@$><=;|&{(,+-*/%^~#)}";

std::vector<std::string> g_matches;  // of the completion under way
std::size_t g_nextMatch = 0;

char* nextMatch(const char*, int state) {
  if (state == 0) g_nextMatch = 0;
  if (g_nextMatch >= g_matches.size()) return nullptr;
  return strdup(g_matches[g_nextMatch++].c_str());  // readline frees it
}

// The completer sees the whole line up to the cursor (so `("x"):up` and `cars["skull"]:ch`
// reach it whole, whatever readline takes for the word) and answers with that text completed;
// readline replaces only the word from `start` on, so the answers lose their first `start` bytes.
char** attemptCompletion(const char* text, int start, int) {
  rl_attempted_completion_over = 1;       // never fall back to completing file names
  rl_completion_append_character = '\0';  // `cars[1]:setSpeed` goes on with `(`, not a space
  g_matches.clear();
  if (!g_editor || !g_editor->completer) return nullptr;
  std::string before(rl_line_buffer, static_cast<std::size_t>(rl_point));
  try {
    for (auto& match : g_editor->completer(before))
      if (match.size() >= static_cast<std::size_t>(start) &&
          match.compare(0, static_cast<std::size_t>(start), before, 0,
                        static_cast<std::size_t>(start)) == 0)
        g_matches.push_back(match.substr(static_cast<std::size_t>(start)));
  } catch (const std::exception& e) {  // nothing may unwind through readline's C frames
    log::warn("repl", std::string("completion failed: ") + e.what());
    return nullptr;
  }
  if (g_matches.empty()) return nullptr;
  return rl_completion_matches(text, nextMatch);
}

// Lists the candidates by their last part (`setSpeed`, `stop`, not `cars[1]:setSpeed`), the way
// shells list file names without their folder.
void displayMatches(char** matches, int count, int) {
  std::string_view common = matches[0];
  std::size_t cut = common.find_last_of(".:");
  cut = cut == std::string_view::npos ? 0 : cut + 1;
  std::vector<char*> shown{matches[0]};
  int width = 0;
  for (int i = 1; i <= count; ++i) {
    char* match = matches[i];
    char* part = std::strncmp(match, matches[0], cut) == 0 ? match + cut : match;
    shown.push_back(part);
    width = std::max(width, static_cast<int>(std::strlen(part)));
  }
  shown.push_back(nullptr);
  rl_crlf();
  rl_display_match_list(shown.data(), count, width);
  rl_forced_update_display();
}

std::string errnoText(int err) {
  return std::strerror(err);
}

}  // namespace

LineEditor::LineEditor(boost::asio::io_context& io, Options options)
    : tty_(::isatty(STDIN_FILENO) && ::isatty(STDOUT_FILENO)),
      options_(std::move(options)),
      input_(io),
      resize_(io) {
  if (g_editor) throw std::logic_error("only one LineEditor at a time (readline is global)");
  int fd = ::fcntl(STDIN_FILENO, F_DUPFD_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error("cannot read the standard input: " + errnoText(errno));
  input_.assign(fd);
  g_editor = this;
  if (!tty_) return;

  rl_readline_name = "pitwall";  // `$if pitwall` in ~/.inputrc
  rl_instream = stdin;
  rl_outstream = stdout;
  rl_catch_signals = 0;   // SIGINT is the REPL's: Ctrl-C interrupts Lua code (repl.cpp)
  rl_catch_sigwinch = 0;  // a resize arrives through the loop (resize_)
  rl_change_environment = 0;
  rl_attempted_completion_function = attemptCompletion;
  rl_completer_word_break_characters = kWordBreaks;
  rl_completion_display_matches_hook = displayMatches;

  // Entries are written with time stamps: that is what lets the file keep a multi-line chunk as
  // one entry (readline's history_multiline_entries).
  using_history();
  history_comment_char = '#';
  history_write_timestamps = 1;
  history_multiline_entries = 1;
  stifle_history(options_.historySize);
  if (options_.historyFile.empty()) return;
  const char* file = options_.historyFile.c_str();
  int hfd = ::open(file, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (hfd < 0) {
    log::warn("repl", "cannot write the history file " + options_.historyFile + ": " +
                          errnoText(errno) +
                          "; this session's lines will not be saved (choose another file with "
                          "--history or PITWALL_HISTORY)");
  } else {
    ::close(hfd);
    historyOk_ = true;
  }
  int err = read_history(file);
  if (err != 0 && err != ENOENT && historyOk_)
    log::warn("repl",
              "cannot read the history file " + options_.historyFile + ": " + errnoText(err));
}

LineEditor::~LineEditor() {
  stop();
  if (tty_) {
    trimHistoryFile();
    rl_attempted_completion_function = nullptr;
    rl_completion_display_matches_hook = nullptr;
    clear_history();
  }
  g_editor = nullptr;
}

void LineEditor::start() {
  if (started_ || stopped_) return;
  started_ = true;
  if (tty_) {
    rl_callback_handler_install(prompt_.c_str(), lineCallback);
    resize_.add(SIGWINCH);
    waitResize();
  }
  waitInput();
}

void LineEditor::stop() {
  if (stopped_) return;
  stopped_ = true;
  boost::system::error_code ignored;
  input_.cancel(ignored);
  resize_.cancel(ignored);
  if (tty_ && started_) {
    bool promptShown = !inHandler_ && !paused_;
    rl_callback_handler_remove();  // puts the terminal back as it was
    if (promptShown) write("\n");  // the prompt stays; the shell goes on below it
  }
}

void LineEditor::pause() {
  if (paused_ || stopped_ || !started_) return;
  paused_ = true;
  boost::system::error_code ignored;
  input_.cancel(ignored);  // an armed wait ends (its handler sees it aborted)
  // Removed inside the line handler, readline shows no prompt when the handler returns; it
  // also puts the terminal back as it was (echo on), as a shell's child finds it.
  if (tty_) rl_callback_handler_remove();
}

void LineEditor::resume() {
  if (!paused_ || stopped_) return;
  paused_ = false;
  if (tty_) {
    if (!atLineStart_) write("\n");  // the prompt starts on a line of its own
    rl_callback_handler_install(prompt_.c_str(), lineCallback);  // draws the prompt
    if (resized_) rl_resize_terminal();
    resized_ = false;
  }
  if (!waiting_) waitInput();
}

int LineEditor::columns() const {
  if (!tty_) return 0;
  int rows = 0, cols = 0;
  rl_get_screen_size(&rows, &cols);
  return cols;
}

void LineEditor::setPrompt(std::string prompt) {
  prompt_ = std::move(prompt);
  // Inside the line handler readline shows the new prompt once the handler returns; at the
  // prompt, the next redisplay does.
  if (tty_ && started_ && !stopped_ && !paused_) rl_set_prompt(prompt_.c_str());
}

void LineEditor::waitInput() {
  waiting_ = true;
  input_.async_wait(boost::asio::posix::stream_descriptor::wait_read,
                    [this](const boost::system::error_code& ec) {
                      waiting_ = false;
                      if (ec == boost::asio::error::operation_aborted || stopped_ || paused_)
                        return;
                      // operation_not_supported: stdin is a regular file or /dev/null, which
                      // epoll cannot wait for; reading those never blocks.
                      if (ec && ec != boost::asio::error::operation_not_supported) {
                        log::warn("repl", "cannot read the standard input: " + ec.message());
                        endOfInput();
                        return;
                      }
                      if (tty_)
                        readTerminal();
                      else
                        readPlain();
                      if (!stopped_ && !paused_) waitInput();
                    });
}

void LineEditor::waitResize() {
  resize_.async_wait([this](const boost::system::error_code& ec, int) {
    if (ec || stopped_) return;
    if (paused_)
      resized_ = true;  // no prompt to redraw: at resume
    else
      rl_resize_terminal();  // the loop only runs this at the prompt, never in a line handler
    waitResize();
  });
}

bool LineEditor::inputReady() const {
  pollfd p{STDIN_FILENO, POLLIN, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLIN | POLLHUP | POLLERR)) != 0;
}

void LineEditor::readTerminal() {
  // Asio waits edge-triggered: everything already typed (a paste) is read now, one byte per call
  // as readline's callback interface wants, or it would sit there until the next key.
  do {
    rl_callback_read_char();
  } while (!stopped_ && !paused_ && inputReady());
}

void LineEditor::readPlain() {
  char buffer[4096];
  ssize_t n = ::read(input_.native_handle(), buffer, sizeof buffer);
  if (n < 0 && (errno == EINTR || errno == EAGAIN)) return;
  if (n < 0) log::warn("repl", "cannot read the standard input: " + errnoText(errno));
  if (n <= 0) {
    if (!plain_.empty() && onLine) {  // a last line without its newline
      std::string last = std::move(plain_);
      plain_.clear();
      onLine(last);
    }
    endOfInput();
    return;
  }
  plain_.append(buffer, static_cast<std::size_t>(n));
  std::size_t from = 0;
  for (std::size_t nl; !stopped_ && (nl = plain_.find('\n', from)) != std::string::npos;) {
    std::string line = plain_.substr(from, nl - from);
    from = nl + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (onLine) onLine(line);
  }
  plain_.erase(0, from);
}

void LineEditor::endOfInput() {
  if (stopped_) return;
  stop();
  if (onEnd) onEnd();
}

void LineEditor::lineCallback(char* line) {
  if (g_editor)
    g_editor->handleLine(line);
  else
    std::free(line);
}

void LineEditor::handleLine(char* raw) {
  std::unique_ptr<char, void (*)(void*)> line(raw, std::free);
  inHandler_ = true;
  atLineStart_ = true;  // readline moved to a new line on Enter
  try {
    if (!raw) {
      // Ctrl-D leaves the cursor on the prompt's line; readline 8.2 moves off it itself when
      // bracketed paste is on, and keeps saying so (rl_eof_found) until told otherwise.
      const char* paste = rl_variable_value("enable-bracketed-paste");
      if (!(rl_eof_found && paste && std::strcmp(paste, "on") == 0)) write("\n");
      rl_eof_found = 0;
      if (onEnd) onEnd();
    } else if (onLine) {
      onLine(raw);
    }
  } catch (const std::exception& e) {  // nothing may unwind through readline's C frames
    log::error("repl", e.what());
  }
  if (!atLineStart_) write("\n");  // the prompt starts on a line of its own
  inHandler_ = false;
}

void LineEditor::write(std::string_view text) {
  if (text.empty()) return;
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
  atLineStart_ = text.back() == '\n';
}

void LineEditor::printAbove(std::string_view text) {
  if (text.empty()) return;
  if (!tty_ || !started_ || stopped_ || inHandler_ || paused_) {  // no prompt on screen now
    write(text);
    return;
  }
  // The way drive-sdk's vehicle-tool and BlueZ's gatttool do it: take the prompt and the typed
  // line off the screen, print, then draw them again below. rl_clear_visible_line (readline 7)
  // erases every screen row the line spans and leaves readline's buffer and point alone, so
  // nothing needs saving and restoring.
  rl_clear_visible_line();
  write(text);
  if (!atLineStart_) write("\n");  // a partial line is finished here: the prompt needs its own
  rl_on_new_line();
  rl_redisplay();
}

void LineEditor::cancelLine() {
  if (!tty_ || !started_ || stopped_ || inHandler_ || paused_) return;
  rl_point = rl_end;
  rl_redisplay();  // the cursor after the typed text, where ^C goes
  write("^C\n");
  rl_callback_sigcleanup();  // out of an incremental search or a half-typed key sequence
  rl_free_line_state();
  using_history();  // Up starts again from the newest entry
  rl_replace_line("", 0);
  rl_mark = 0;
  rl_set_prompt(prompt_.c_str());
  rl_on_new_line();
  rl_redisplay();
}

void LineEditor::addHistory(const std::string& entry) {
  if (!tty_ || entry.empty()) return;
  HIST_ENTRY* last = history_length > 0 ? history_get(history_base + history_length - 1) : nullptr;
  if (last && entry == last->line) return;  // the same again: once is enough
  add_history(entry.c_str());
  if (!historyOk_) return;
  if (int err = append_history(1, options_.historyFile.c_str())) {
    historyOk_ = false;  // one warning, not one per line
    log::warn("repl", "cannot write the history file " + options_.historyFile + ": " +
                          errnoText(err) + "; this session's lines will not be saved");
    return;
  }
  historyAppended_ = true;
}

// Entries are appended one by one (a crash loses none; two sessions at once keep both); on the
// way out the file is cut back to the newest historySize entries, counted as entries: a
// multi-line chunk is cut whole or not at all (history_truncate_file counts lines).
void LineEditor::trimHistoryFile() {
  if (!historyOk_ || !historyAppended_) return;
  const char* file = options_.historyFile.c_str();
  unstifle_history();
  clear_history();
  if (read_history(file) != 0 || history_length <= options_.historySize) return;
  stifle_history(options_.historySize);  // drops the oldest
  if (int err = write_history(file))
    log::warn("repl",
              "cannot trim the history file " + options_.historyFile + ": " + errnoText(err));
}

}  // namespace pitwall::cli
