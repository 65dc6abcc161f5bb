#pragma once
// What pitwall prints for the person at the terminal: a script's print and io.write, and the
// log. Straight to stdout (the log to stderr) by default; while a REPL prompt is on the
// terminal, the REPL sets a writer that prints above the prompt without garbling the line being
// typed (engine/cli/line_editor.hpp).
#include <cstdint>
#include <functional>
#include <string_view>

namespace pitwall::console {

using Writer = std::function<void(std::string_view text)>;

// Where output goes from now on; an empty writer restores stdout.
void setWriter(Writer writer);
bool hasWriter();
// Text as a script wrote it: any number of lines, possibly without a final newline.
void write(std::string_view text);
// How many writes reached the terminal so far — this console's and the log's: a drawing that
// redraws in place (pitwall.board) starts anew below when anything came in between, instead of
// drawing over it.
std::uint64_t outputCount();
void noteOutput();

}  // namespace pitwall::console
