#pragma once
// Logging with levels, to stderr. Each line carries the engine clock time when a clock is set,
// so virtual-time runs log simulated seconds.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace pitwall::log {

enum class Level { Debug = 0, Info = 1, Warn = 2, Error = 3, Off = 4 };

void setLevel(Level level);
Level level();
// Parses "debug", "info", "warn", "error", "off"; nullopt for anything else.
std::optional<Level> parseLevel(std::string_view text);
// Source of the time stamp printed on each line (seconds); none prints no stamp.
void setTimeSource(std::function<double()> seconds);
// Where lines go; default is stderr. Tests capture lines through this.
void setSink(std::function<void(Level, std::string_view line)> sink);

// Taps see every line written at Info or above, whatever the level shown (the race view's event
// log); a tap must not log. removeTap takes the id addTap returned.
using Tap = std::function<void(Level, std::string_view component, std::string_view message)>;
std::uint64_t addTap(Tap tap);
void removeTap(std::uint64_t id);

void write(Level level, std::string_view component, std::string_view message);
inline void debug(std::string_view c, std::string_view m) {
  write(Level::Debug, c, m);
}
inline void info(std::string_view c, std::string_view m) {
  write(Level::Info, c, m);
}
inline void warn(std::string_view c, std::string_view m) {
  write(Level::Warn, c, m);
}
inline void error(std::string_view c, std::string_view m) {
  write(Level::Error, c, m);
}

}  // namespace pitwall::log
