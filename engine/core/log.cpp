#include "engine/core/log.hpp"

#include "engine/core/console.hpp"

#include <cstdio>
#include <vector>

namespace pitwall::log {
namespace {
Level g_level = Level::Info;
std::function<double()> g_time;
std::function<void(Level, std::string_view)> g_sink;
std::vector<std::pair<std::uint64_t, Tap>> g_taps;
std::uint64_t g_nextTap = 1;

const char* levelName(Level l) {
  switch (l) {
    case Level::Debug:
      return "debug";
    case Level::Info:
      return "info";
    case Level::Warn:
      return "warn";
    case Level::Error:
      return "error";
    case Level::Off:
      return "off";
  }
  return "?";
}
}  // namespace

void setLevel(Level level) {
  g_level = level;
}
Level level() {
  return g_level;
}

std::optional<Level> parseLevel(std::string_view text) {
  for (Level l : {Level::Debug, Level::Info, Level::Warn, Level::Error, Level::Off})
    if (text == levelName(l)) return l;
  return std::nullopt;
}

void setTimeSource(std::function<double()> seconds) {
  g_time = std::move(seconds);
}
void setSink(std::function<void(Level, std::string_view)> sink) {
  g_sink = std::move(sink);
}

std::uint64_t addTap(Tap tap) {
  g_taps.emplace_back(g_nextTap, std::move(tap));
  return g_nextTap++;
}
void removeTap(std::uint64_t id) {
  std::erase_if(g_taps, [id](const auto& t) { return t.first == id; });
}

void write(Level level, std::string_view component, std::string_view message) {
  if (level >= Level::Info && !g_taps.empty()) {
    static bool tapping = false;  // a tap that logs is not called again for its own line
    if (!tapping) {
      tapping = true;
      auto taps = g_taps;
      for (auto& [id, tap] : taps) tap(level, component, message);
      tapping = false;
    }
  }
  if (level < g_level || g_level == Level::Off) return;
  std::string line;
  if (g_time) {
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "[%9.3f] ", g_time());
    line += stamp;
  }
  line += levelName(level);
  line += ' ';
  line += component;
  line += ": ";
  line += message;
  if (g_sink) {
    g_sink(level, line);
    return;
  }
  line += '\n';
  console::noteOutput();
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace pitwall::log
