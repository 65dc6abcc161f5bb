// pitwall scan: being written (issue 3).
#include <iostream>

#include "engine/cli/commands.hpp"

namespace pitwall::cli {
int scan(const ScanOptions&) {
  std::cerr << "pitwall scan: not built yet\n";
  return 2;
}
}  // namespace pitwall::cli
