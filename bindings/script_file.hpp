#pragma once
// A script's file: read, named as messages show it (relative to the current folder where it is
// inside it: `examples/lap.lua:12:`, not `/home/…/examples/lap.lua:12:`), and compiled as text.
// Commands check their scripts with check() before they connect a car: a missing or broken
// script is refused at once, not after a minute of Bluetooth scanning.
#include <lua.hpp>

#include <optional>
#include <string>

#include "engine/core/result.hpp"

namespace pitwall::script_file {

// `path` relative to the current folder when the file is inside it (or below), else as given.
std::string shownPath(const std::string& path);

// Reads and compiles the script at `path` as a text chunk named "@" + shownPath(path) (a first
// line starting with '#' is skipped, as lua does), leaving the function on L's stack; or the
// reason it cannot, with nothing pushed: "cannot open nosuch.lua: no such file", a syntax error.
Result<bool, std::string> load(lua_State* L, const std::string& path);

// The same in a Lua state of its own, run nothing: nullopt when the script would load.
std::optional<std::string> check(const std::string& path);

}  // namespace pitwall::script_file
