// pitwall emulate-car: being written (issue 3).
#include <iostream>

#include "engine/cli/commands.hpp"

namespace pitwall::cli {
int emulateCar(const EmulateOptions&) {
  std::cerr << "pitwall emulate-car: not built yet\n";
  return 2;
}
}  // namespace pitwall::cli
