// pitwall repl (placeholder until the REPL lands; being written now).
#include <iostream>

#include "engine/cli/commands.hpp"

namespace pitwall::cli {

int repl(const ReplOptions&) {
  std::cerr << "pitwall repl: not built yet\n";
  return 2;
}

}  // namespace pitwall::cli
