#include "engine/core/console.hpp"

#include <cstdio>

namespace pitwall::console {
namespace {
Writer g_writer;
}

void setWriter(Writer writer) {
  g_writer = std::move(writer);
}

bool hasWriter() {
  return static_cast<bool>(g_writer);
}

void write(std::string_view text) {
  if (g_writer) return g_writer(text);
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
}

}  // namespace pitwall::console
