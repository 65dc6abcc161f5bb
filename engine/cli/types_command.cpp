// pitwall types [DIR]: the LuaLS definitions of the whole Lua API (docs/editor.md), generated in
// a Lua world of this binary (scripts/pitwall/types.lua) and written to DIR/types/, with a
// DIR/.luarc.json that points the language server at them.
#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "bindings/lua_json.hpp"
#include "bindings/object_types.hpp"
#include "engine/cli/fail.hpp"
#include "engine/cli/options.hpp"
#include "engine/cli/session.hpp"
#include "engine/core/result.hpp"
#include "engine/sim/track.hpp"

namespace pitwall::cli {

namespace fs = std::filesystem;

namespace {

struct TypesOptions {
  std::string dir = ".";
  bool check = false;       // compare with DIR/types instead of writing
  bool luarc = true;        // write DIR/.luarc.json too
  std::string completions;  // write an editor's completions as JSON to this file instead
};

// Runs `chunk`, called with the registered object types, in a Lua world of this binary made as
// `pitwall test` makes one (the simulator, pitwall.sim, and `expect`), and hands its one result
// to `take`; an error message when the annotations and the binary disagree (the generator names
// every difference) or the chunk fails.
std::string inTypesWorld(const char* chunk, const std::function<void(lua_State*)>& take) {
  auto track = sim::namedLayout("oval");
  Session session(ClockKind::Virtual, std::move(*track), 1);
  HostOptions host;
  host.test_mode = true;
  host.budget = std::chrono::milliseconds(0);  // the generator's one call takes what it takes
  session.startHost(host);
  lua_State* L = session.host().state();
  const int top = lua_gettop(L);
  std::string error;
  if (luaL_loadstring(L, chunk) != LUA_OK) {
    error = lua_tostring(L, -1);
  } else {
    lua::pushObjectTypes(L);
    if (!session.host().callCapturing(1, 1, error)) {
      error = error.substr(0, error.find("\nstack traceback:"));  // the differences, named
    } else {
      try {
        take(L);
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
  }
  lua_settop(L, top);
  return error;
}

// The definition files, path under types/ → text; an error message when the annotations and the
// binary disagree.
Result<std::map<std::string, std::string>, std::string> generate() {
  std::map<std::string, std::string> files;
  std::string error =
      inTypesWorld("return require('pitwall.types').generate(...)", [&](lua_State* L) {
        if (!lua_istable(L, -1)) return;
        lua_pushnil(L);
        while (lua_next(L, -2)) {
          if (lua_type(L, -2) == LUA_TSTRING && lua_type(L, -1) == LUA_TSTRING)
            files[lua_tostring(L, -2)] = lua_tostring(L, -1);
          lua_pop(L, 1);
        }
      });
  if (!error.empty()) return Unexpected{error};
  return files;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool writeFile(const fs::path& path, const std::string& text) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) {
    fail("types", "cannot write " + path.string() + ": " + std::strerror(errno));
    return false;
  }
  return true;
}

// --completions FILE: what an editor offers, from the definitions generate() makes (types.lua
// `completions`: prefix → [{label, type, detail, info}]), as JSON.
int writeCompletions(const fs::path& file) {
  nlohmann::json out;
  const std::string error = inTypesWorld(
      "local types = require('pitwall.types') return types.completions(types.generate(...))",
      [&](lua_State* L) {
        lua::CopyBudget budget(L, "pitwall types --completions", std::size_t{64} << 20);
        out =
            lua::toJson(L, -1, {"pitwall types --completions", "the file"}, budget, "completions");
      });
  if (!error.empty()) return fail("types", error, 1);
  if (!writeFile(file, out.dump(1) + "\n")) return 2;
  std::size_t count = 0;
  for (const auto& [prefix, list] : out.items()) count += list.size();
  std::cout << "wrote " << count << " completions under " << out.size() << " prefixes to "
            << file.string() << "\n";
  return 0;
}

// DIR/.luarc.json: made when there is none; one that exists gets "types" added to its
// workspace.library (and the runtime version, when it names none). One that is not JSON is
// left alone, with a message saying what to add.
int writeLuarc(const fs::path& dir) {
  const fs::path path = dir / ".luarc.json";
  nlohmann::json config = nlohmann::json::object();
  const bool existed = fs::exists(path);
  if (existed) {
    const std::string text = readFile(path);
    config = nlohmann::json::parse(text, nullptr, false, true);
    // Rewriting would drop the comments: a file that has them is the user's to edit.
    const bool comments =
        !config.is_discarded() && nlohmann::json::parse(text, nullptr, false, false).is_discarded();
    if (comments && config.is_object()) {
      return fail("types",
                  path.string() +
                      " has comments, which rewriting it would lose: left as it is; add "
                      "\"types\" to its \"workspace.library\" yourself",
                  1);
    }
    if (config.is_discarded() || !config.is_object()) {
      return fail("types",
                  path.string() +
                      " is not a JSON object: left as it is; add \"types\" to its "
                      "\"workspace.library\" yourself",
                  1);
    }
  } else {
    config["$schema"] =
        "https://raw.githubusercontent.com/LuaLS/vscode-lua/master/setting/schema.json";
  }
  // LuaLS takes both forms: "workspace.library" and {"workspace": {"library": …}}.
  bool listed = false;
  try {
    nlohmann::json& library = config.contains("workspace.library") ? config["workspace.library"]
                                                                   : config["workspace"]["library"];
    // one folder as a string is a list of one: kept, not replaced
    if (library.is_string()) library = nlohmann::json::array({library});
    if (!library.is_array()) library = nlohmann::json::array();
    for (const auto& entry : library)
      if (entry.is_string() &&
          (fs::path(entry.get<std::string>()).lexically_normal() / "").string() == "types/")
        listed = true;
    if (!listed) library.push_back("types");
    if (!config.contains("runtime.version") &&
        !(config.contains("runtime") && config["runtime"].contains("version")))
      config["runtime"]["version"] = "Lua 5.4";
  } catch (const nlohmann::json::exception&) {
    return fail("types",
                path.string() +
                    " has a \"workspace\" or \"runtime\" that is not an object: left as "
                    "it is; add \"types\" to its workspace.library yourself",
                1);
  }
  if (existed && listed) {
    std::cout << "kept " << path.string() << " (it lists types already)\n";
    return 0;
  }
  if (!writeFile(path, config.dump(2) + "\n")) return 2;
  std::cout << (existed ? "updated " : "wrote ") << path.string()
            << (existed ? " (added \"types\" to workspace.library)" : "") << "\n";
  return 0;
}

int types(const TypesOptions& options) {
  if (!options.completions.empty()) return writeCompletions(options.completions);
  auto files = generate();
  if (!files) {
    return fail("types", files.error(), 1);
  }
  const fs::path dir = options.dir;
  if (options.check) {
    int differ = 0;
    for (const auto& [name, text] : *files) {
      const fs::path path = dir / "types" / name;
      if (!fs::exists(path)) {
        std::cerr << "missing: " << path.string() << "\n";
        ++differ;
      } else if (readFile(path) != text) {
        std::cerr << "differs: " << path.string() << "\n";
        ++differ;
      }
    }
    std::error_code ec;
    if (fs::is_directory(dir / "types", ec))
      for (const auto& e : fs::recursive_directory_iterator(dir / "types", ec)) {
        const std::string name = fs::relative(e.path(), dir / "types", ec).generic_string();
        if (e.is_regular_file() && e.path().extension() == ".lua" && !files->count(name)) {
          std::cerr << "not generated (stale): " << e.path().string() << "\n";
          ++differ;
        }
      }
    if (differ) {
      return fail("types",
                  std::to_string(differ) + " file(s) of " + (dir / "types").string() +
                      " are not what this binary generates; regenerate with `pitwall "
                      "types " +
                      dir.string() + "`",
                  1);
    }
    std::cout << (dir / "types").string() << " is up to date (" << files->size() << " files)\n";
    return 0;
  }
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return fail("types", dir.string() + " is not a folder");
  }
  for (const auto& [name, text] : *files)
    if (!writeFile(dir / "types" / name, text)) return 2;
  std::cout << "wrote " << files->size() << " definition files to " << (dir / "types").string()
            << "\n";
  return options.luarc ? writeLuarc(dir) : 0;
}

}  // namespace

Command addTypesCommand(CLI::App& app) {
  auto options = std::make_shared<TypesOptions>();
  auto* cmd = app.add_subcommand(
      "types",
      "Write the Lua API's definitions for the Lua language server (LuaLS) to DIR/types and a "
      "DIR/.luarc.json that uses them (docs/editor.md)");
  cmd->add_option("dir", options->dir, "The project folder (default: the current folder)");
  cmd->add_flag("--check", options->check,
                "Write nothing: exit 1 when DIR/types is not what this binary generates");
  cmd->add_flag("!--no-luarc", options->luarc,
                "Write only DIR/types, no DIR/.luarc.json (the repository's own types/)");
  cmd->add_option("--completions", options->completions,
                  "Write what a code editor offers after car:, ctx., pitwall., … as JSON to FILE, "
                  "from the same definitions, instead of DIR/types (the view's code editor)");
  return {cmd, [options] { return cli::types(*options); }};
}

}  // namespace pitwall::cli
