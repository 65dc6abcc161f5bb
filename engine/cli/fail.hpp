#pragma once
// The one way a command says it cannot go on: "pitwall COMMAND: why" on stderr (the sentence
// names what was wrong and what to do), and the exit status it ends with (2 by default: the
// command line or the setup; 1: the run itself).
#include <iostream>
#include <string_view>

namespace pitwall::cli {

inline int fail(std::string_view command, std::string_view why, int status = 2) {
  std::cerr << "pitwall " << command << ": " << why << "\n";
  return status;
}

}  // namespace pitwall::cli
