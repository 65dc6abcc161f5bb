#include "bindings/script_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include "engine/core/printable.hpp"

namespace pitwall::script_file {

namespace fs = std::filesystem;

std::string shownPath(const std::string& path) {
  std::error_code ec;
  const fs::path given(path);
  if (given.is_relative()) return given.lexically_normal().string();
  const fs::path cwd = fs::current_path(ec);
  if (ec) return path;
  const fs::path relative = given.lexically_normal().lexically_relative(cwd);
  if (relative.empty() || *relative.begin() == "..") return path;
  return relative.string();
}

Result<bool, std::string> load(lua_State* L, const std::string& path) {
  const std::string shown = shownPath(path);
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Unexpected{"cannot open " + shown + ": it is a folder"};
  // A pipe or a device would be read up once by the check and found empty by the run.
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
    return Unexpected{"cannot open " + printable(shown, 200) +
                      ": it is not a file (a pipe or a device); save the script to a file"};
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    return Unexpected{"cannot open " + printable(shown, 200) + ": " +
                      (error == ENOENT ? std::string("no such file") : std::strerror(error))};
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t start = 0;
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) start = 3;  // a UTF-8 byte order mark
  std::string_view code(text);
  code.remove_prefix(start);
  if (!code.empty() && code[0] == '#') {  // `#!/usr/bin/env pitwall run`: keep the line count
    auto eol = code.find('\n');
    code = eol == std::string_view::npos ? std::string_view() : code.substr(eol);
  }
  const std::string chunkname = "@" + shown;
  if (luaL_loadbufferx(L, code.data(), code.size(), chunkname.c_str(), "t") != LUA_OK) {
    std::string err = lua_tostring(L, -1) ? lua_tostring(L, -1) : "cannot load " + shown;
    lua_pop(L, 1);
    return Unexpected{err};
  }
  return true;
}

std::optional<std::string> check(const std::string& path) {
  std::unique_ptr<lua_State, decltype(&lua_close)> L(luaL_newstate(), &lua_close);
  if (!L) return "cannot check " + path + ": out of memory";
  auto loaded = load(L.get(), path);
  if (!loaded) return loaded.error();
  return std::nullopt;
}

}  // namespace pitwall::script_file
