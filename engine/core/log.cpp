#include "engine/core/log.hpp"

#include "engine/core/console.hpp"

#include <cstdio>

namespace pitwall::log {
namespace {
Level g_level = Level::Info;
std::function<double()> g_time;
std::function<void(Level, std::string_view)> g_sink;

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

void write(Level level, std::string_view component, std::string_view message) {
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
