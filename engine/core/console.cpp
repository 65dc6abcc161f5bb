#include "engine/core/console.hpp"

#include <atomic>
#include <cstdio>

namespace pitwall::console {
namespace {
Writer g_writer;
std::atomic<std::uint64_t> g_output{0};  // (the log may write from any thread)
}  // namespace

std::uint64_t outputCount() {
  return g_output.load(std::memory_order_relaxed);
}

void noteOutput() {
  g_output.fetch_add(1, std::memory_order_relaxed);
}

void setWriter(Writer writer) {
  g_writer = std::move(writer);
}

bool hasWriter() {
  return static_cast<bool>(g_writer);
}

void write(std::string_view text) {
  noteOutput();
  if (g_writer) return g_writer(text);
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
}

}  // namespace pitwall::console
