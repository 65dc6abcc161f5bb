#include "bindings/sandbox.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "bindings/interrupt.hpp"
#include "bindings/metatables.hpp"

namespace pitwall::sandbox {

namespace {

// Once the cap is reached, the engine still needs a little memory to report the error and end
// the run (error messages, tracebacks): allocations up to this much above the cap are served.
constexpr std::size_t kHeadroom = std::size_t{4} << 20;
constexpr int kRefusals = 16;

constexpr const char* kBinaryRefused =
    "precompiled (binary) chunks are refused: pitwall runs Lua source only, as Lua does not "
    "verify bytecode (docs/safety.md)";

void* allocate(void* ud, void* ptr, std::size_t osize, std::size_t nsize) {
  auto* m = static_cast<Memory*>(ud);
  const std::size_t old = ptr ? osize : 0;  // without ptr, osize says what kind of object
  if (nsize == 0) {
    std::free(ptr);
    m->used -= old;
    return nullptr;
  }
  // Only a call from the engine into Lua is refused memory: there a refusal is a Lua error the
  // engine catches. Outside one (the engine pushing an event's values) it would be a panic.
  if (nsize > old && m->limit != 0 && interrupt::inCall()) {
    const std::size_t cap = m->exceeded ? m->limit + kHeadroom : m->limit;
    if (m->used + m->outside + (nsize - old) > cap) {
      // The retry after Lua's emergency collection: the script does hold that much. (Lua skips
      // the collection while one runs: many refusals in a row say the same.)
      const bool retry = ptr == m->refusedPtr && osize == m->refusedOld && nsize == m->refusedNew;
      if (!m->exceeded && (retry || ++m->refusals >= kRefusals)) {
        m->exceeded = true;
        interrupt::abortRunning(memoryMessage(*m));
      }
      m->refusedPtr = ptr;
      m->refusedOld = osize;
      m->refusedNew = nsize;
      return nullptr;
    }
  }
  void* p = std::realloc(ptr, nsize);
  if (p) m->used = m->used - old + nsize;
  return p;
}

int panic(lua_State* L) {
  const char* msg = lua_tostring(L, -1);
  std::fprintf(stderr, "pitwall: unprotected error in the Lua world: %s\n",
               msg ? msg : "(error object is not a string)");
  return 0;  // Lua aborts
}

bool isBinary(const char* s, std::size_t n) {
  return n > 0 && s[0] == LUA_SIGNATURE[0];
}

// A loaded chunk gets `env` (the argument at envIdx, 0: none) as its first upvalue, as load and
// loadfile do; a failure is `fail, message`.
int loaded(lua_State* L, int status, int envIdx) {
  if (status != LUA_OK) {
    luaL_pushfail(L);
    lua_insert(L, -2);
    return 2;
  }
  if (envIdx != 0) {
    lua_pushvalue(L, envIdx);
    if (!lua_setupvalue(L, -2, 1)) lua_pop(L, 1);
  }
  return 1;
}

constexpr int kPieceSlot = 5;  // where load keeps the reader function's last piece alive

// A reader function's pieces, one call each, until it returns nil or "".
const char* nextPiece(lua_State* L, void*, std::size_t* size) {
  luaL_checkstack(L, 2, "too many nested functions");
  lua_pushvalue(L, 1);
  lua_call(L, 0, 1);
  if (lua_isnil(L, -1)) {
    lua_pop(L, 1);
    *size = 0;
    return nullptr;
  }
  if (!lua_isstring(L, -1)) luaL_error(L, "reader function must return a string");
  lua_replace(L, kPieceSlot);
  return lua_tolstring(L, kPieceSlot, size);
}

// load(chunk [, chunkname [, mode [, env]]]), text only whatever the mode says. Written here
// rather than wrapping Lua's own, so that no reference to that one is left for a script to find.
int loadText(lua_State* L) {
  std::size_t len = 0;
  const char* text = lua_tolstring(L, 1, &len);
  luaL_optstring(L, 3, "bt");
  const int envIdx = lua_isnone(L, 4) ? 0 : 4;
  int status;
  if (text) {
    if (isBinary(text, len)) {
      luaL_pushfail(L);
      lua_pushfstring(L, "load: %s", kBinaryRefused);
      return 2;
    }
    const char* name = luaL_optstring(L, 2, text);
    status = luaL_loadbufferx(L, text, len, name, "t");
  } else {
    const char* name = luaL_optstring(L, 2, "=(load)");
    luaL_checktype(L, 1, LUA_TFUNCTION);
    lua_settop(L, kPieceSlot);
    status = lua_load(L, nextPiece, nullptr, name, "t");
  }
  return loaded(L, status, envIdx);
}

// loadfile([filename [, mode [, env]]]): text only.
int loadfileText(lua_State* L) {
  const char* fname = luaL_optstring(L, 1, nullptr);
  return loaded(L, luaL_loadfilex(L, fname, "t"), lua_isnone(L, 3) ? 0 : 3);
}

int dofileText(lua_State* L) {
  const char* fname = luaL_optstring(L, 1, nullptr);
  lua_settop(L, 1);
  if (luaL_loadfilex(L, fname, "t") != LUA_OK) return lua_error(L);
  lua_call(L, 0, LUA_MULTRET);
  return lua_gettop(L) - 1;
}

// Modules compiled in this process, by file name, with the text they were compiled from. A hot
// reload makes a new Lua world that requires the same files again; loading the bytecode this
// process made from the same text skips the parser, which was most of a reload's cost
// (docs/performance.md "Issue 20"). The bytecode never comes from outside: the file is read once,
// its text compiled, and a later load uses the bytecode only when the text read then is the same.
// Only regular files up to kMaxModule take part, and the cache stops growing at kMaxCache; others
// load as Lua loads them (streamed, so a huge or endless file fails at its first bad token and
// costs no memory outside the script's cap). Single-threaded, as the loop.
constexpr std::size_t kMaxModule = std::size_t{1} << 20;
constexpr std::size_t kMaxCache = std::size_t{16} << 20;

struct CompiledModule {
  std::string text;
  std::string bytecode;
};

struct ModuleCache {
  std::unordered_map<std::string, CompiledModule> modules;
  std::size_t bytes = 0;
};

ModuleCache& moduleCache() {
  static ModuleCache cache;
  return cache;
}

int appendBytes(lua_State*, const void* bytes, std::size_t size, void* out) {
  static_cast<std::string*>(out)->append(static_cast<const char*>(bytes), size);
  return 0;
}

// The whole text of a regular file of at most kMaxModule bytes; nullopt for anything else.
std::optional<std::string> readSmallFile(const char* filename) {
  int fd = ::open(filename, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::optional<std::string> text;
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
      static_cast<std::size_t>(st.st_size) <= kMaxModule) {
    std::string buffer(static_cast<std::size_t>(st.st_size) + 1, '\0');  // +1: sees growth
    std::size_t got = 0;
    for (;;) {
      ssize_t n = ::read(fd, buffer.data() + got, buffer.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
      if (got == buffer.size()) break;  // grew since fstat: not a module to cache
    }
    if (got < buffer.size()) {
      buffer.resize(got);
      text = std::move(buffer);
    }
  }
  ::close(fd);
  return text;
}

// luaL_loadfilex(L, filename, "t") through the cache. The text is compiled as luaL_loadfilex
// would: a UTF-8 byte order mark is skipped, and a first line starting with '#' (a shebang) is
// emptied, keeping its newline so that line numbers stay those of the file.
int loadModuleFile(lua_State* L, const char* filename) {
  std::optional<std::string> text = readSmallFile(filename);
  if (!text) return luaL_loadfilex(L, filename, "t");
  ModuleCache& cache = moduleCache();
  const std::string chunkname = std::string("@") + filename;
  if (auto it = cache.modules.find(filename); it != cache.modules.end() && it->second.text == *text)
    return luaL_loadbufferx(L, it->second.bytecode.data(), it->second.bytecode.size(),
                            chunkname.c_str(), "b");
  std::string_view code(*text);
  if (code.substr(0, 3) == "\xEF\xBB\xBF") code.remove_prefix(3);
  if (!code.empty() && code[0] == '#') {
    auto eol = code.find('\n');
    code = eol == std::string_view::npos ? std::string_view() : code.substr(eol);
  }
  int status = luaL_loadbufferx(L, code.data(), code.size(), chunkname.c_str(), "t");
  if (status != LUA_OK) return status;
  std::string bytecode;
  if (lua_dump(L, appendBytes, &bytecode, 0) != 0) return LUA_OK;
  if (auto it = cache.modules.find(filename); it != cache.modules.end()) {
    cache.bytes -= it->second.text.size() + it->second.bytecode.size();
    cache.modules.erase(it);
  }
  const std::size_t size = text->size() + bytecode.size();
  if (cache.bytes + size <= kMaxCache) {
    cache.bytes += size;
    cache.modules[filename] = CompiledModule{std::move(*text), std::move(bytecode)};
  }
  return LUA_OK;
}

// require's searcher for Lua files, text only (Lua's own loads binary files too).
int searchLuaText(lua_State* L) {
  const char* name = luaL_checkstring(L, 1);
  lua_getfield(L, lua_upvalueindex(1), "searchpath");
  lua_pushstring(L, name);
  if (lua_isstring(L, lua_upvalueindex(2)))  // a driver world's: fixed when it opened
    lua_pushvalue(L, lua_upvalueindex(2));
  else
    lua_getfield(L, lua_upvalueindex(1), "path");
  if (!lua_isstring(L, -1)) luaL_error(L, "'package.path' must be a string");
  lua_call(L, 2, 2);
  if (lua_isnil(L, -2)) return 1;  // the "no file …" lines
  lua_pop(L, 1);
  const char* filename = lua_tostring(L, -1);
  if (loadModuleFile(L, filename) != LUA_OK)
    return luaL_error(L, "error loading module '%s' from file '%s':\n\t%s", name, filename,
                      lua_tostring(L, -1));
  lua_pushstring(L, filename);
  return 2;
}

int refused(lua_State* L) {
  return luaL_error(L, "%s is not available to scripts: %s", lua_tostring(L, lua_upvalueindex(1)),
                    lua_tostring(L, lua_upvalueindex(2)));
}

void refuse(lua_State* L, const char* library, const char* name, const char* why) {
  lua_getglobal(L, library);
  if (!lua_istable(L, -1)) {
    lua_pop(L, 1);
    return;
  }
  lua_pushfstring(L, "%s.%s", library, name);
  lua_pushstring(L, why);
  lua_pushcclosure(L, refused, 2);
  lua_setfield(L, -2, name);
  lua_pop(L, 1);
}

// setmetatable(t, mt) without finalizers: a __gc runs where Lua turns debug hooks off (nothing
// interrupts it: not the budget, not Ctrl-C) and when the world closes (past the memory cap).
int setmetatableNoGc(lua_State* L) {
  if (lua_type(L, 2) == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    if (lua_rawget(L, 2) != LUA_TNIL)
      return luaL_error(L,
                        "setmetatable: a __gc finalizer is refused: it would run where nothing can "
                        "interrupt it; close resources with a to-be-closed variable (local x "
                        "<close>) or in pitwall.onUnload");
    lua_pop(L, 1);
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, 1);
  return 1;
}

// io.lines(filename, …) reads a file; io.lines() would read the terminal.
int linesOfFile(lua_State* L) {
  if (lua_isnoneornil(L, 1))
    return luaL_error(L,
                      "io.lines() without a file name would read the terminal and block the "
                      "engine; give a file name");
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

}  // namespace

std::string memoryMessage(const Memory& memory) {
  if (memory.driver)
    return "driver memory limit of " + std::to_string(memory.limit >> 20) +
           " MB reached (the driver keeps too much: drop what it no longer needs, or raise the "
           "limit with --driver-memory MB)";
  return "script memory limit of " + std::to_string(memory.limit >> 20) +
         " MB reached (the script keeps too much: drop what it no longer needs, or raise the "
         "limit with --lua-memory MB)";
}

lua_State* newState(Memory& memory) {
  lua_State* L = lua_newstate(allocate, &memory);
  if (L) lua_atpanic(L, panic);
  return L;
}

void restrict(lua_State* L) {
  lua_pushcfunction(L, loadText);
  lua_setglobal(L, "load");
  lua_getglobal(L, "setmetatable");
  lua_pushcclosure(L, setmetatableNoGc, 1);
  lua_setglobal(L, "setmetatable");
  lua_pushcfunction(L, loadfileText);
  lua_setglobal(L, "loadfile");
  lua_pushcfunction(L, dofileText);
  lua_setglobal(L, "dofile");

  lua_getglobal(L, "package");
  lua_getfield(L, -1, "searchers");
  lua_pushvalue(L, -2);
  lua_pushcclosure(L, searchLuaText, 1);
  lua_rawseti(L, -2, 2);
  lua_pop(L, 2);

  // The debug library keeps what reads.
  lua_getglobal(L, "debug");
  if (lua_istable(L, -1)) {
    // getupvalue and getlocal would reach into the engine's C functions and their stacks.
    static const char* const kept[] = {"traceback", "getinfo", "getmetatable", "getuservalue",
                                       "upvalueid"};
    lua_createtable(L, 0, 5);
    for (const char* name : kept) {
      lua_getfield(L, -2, name);
      lua_setfield(L, -2, name);
    }
    // debug.getmetatable answers as getmetatable does (a locked metatable's public face, see
    // bindings/metatables.hpp): Lua's own would hand out the engine's metatables themselves.
    lua_getglobal(L, "getmetatable");
    lua_setfield(L, -2, "getmetatable");
    lua_setglobal(L, "debug");
  }
  lua_pop(L, 1);
  // debug is also reachable as package.loaded.debug
  lua_getglobal(L, "package");
  lua_getfield(L, -1, "loaded");
  lua_getglobal(L, "debug");
  lua_setfield(L, -2, "debug");
  lua_pop(L, 2);

  constexpr const char* kBlocks =
      "it would block the engine's one loop (and with it Ctrl-C and the cars' stop); run "
      "other programs outside the script";
  refuse(L, "io", "read", "it reads the terminal and would block the engine; use io.open(file)");
  refuse(L, "io", "input", "it reads the terminal and would block the engine; use io.open(file)");
  refuse(L, "package", "loadlib",
         "it calls any function of any library; a C module loads with require, through "
         "package.cpath");
  lua_getglobal(L, "io");
  lua_pushnil(L);
  lua_setfield(L, -2, "stdin");  // reading the terminal would block the engine
  lua_pop(L, 1);
  refuse(L, "io", "popen", kBlocks);
  refuse(L, "os", "execute", kBlocks);
  // The metatables Lua's own libraries made are locked too: the strings' (its __index stays the
  // string library, which scripts may extend) and the files' (a __gc planted there would run for
  // every file handle, with hooks off).
  lua_pushliteral(L, "");
  if (lua_getmetatable(L, -1)) {
    lua::lockMetatable(L, -1, true, "string");
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  if (luaL_getmetatable(L, LUA_FILEHANDLE) == LUA_TTABLE) lua::lockMetatable(L, -1);
  lua_pop(L, 1);
  lua_getglobal(L, "io");
  if (lua_istable(L, -1)) {
    lua_getfield(L, -1, "lines");
    lua_pushcclosure(L, linesOfFile, 1);
    lua_setfield(L, -2, "lines");
  }
  lua_pop(L, 1);
}

void restrictToLibrary(lua_State* L, const std::string& path) {
  constexpr const char* kNoFiles =
      "a driver reads and writes no file (docs/drivers.md); what it needs comes from its car, "
      "its ctx and the shipped library (require \"pitwall.drivers\")";
  for (const char* name : {"open", "lines", "input", "output", "close", "tmpfile", "popen"})
    refuse(L, "io", name, kNoFiles);
  for (const char* name : {"remove", "rename", "tmpname", "getenv", "setlocale"})
    refuse(L, "os", name, kNoFiles);
  lua_getglobal(L, "io");
  for (const char* name : {"stdin", "stdout", "stderr"}) {
    lua_pushnil(L);
    lua_setfield(L, -2, name);
  }
  lua_pop(L, 1);
  lua_pushliteral(L, "loadfile");
  lua_pushstring(L, kNoFiles);
  lua_pushcclosure(L, refused, 2);
  lua_setglobal(L, "loadfile");
  lua_pushliteral(L, "dofile");
  lua_pushstring(L, kNoFiles);
  lua_pushcclosure(L, refused, 2);
  lua_setglobal(L, "dofile");
  // require: the shipped library only, from a path fixed now (package.path does not move it);
  // no C searchers (Lua's own package.cpath and all-in-one loaders).
  lua_getglobal(L, "package");
  lua_pushstring(L, path.c_str());
  lua_setfield(L, -2, "path");
  lua_pushliteral(L, "");
  lua_setfield(L, -2, "cpath");
  lua_getfield(L, -1, "searchers");
  lua_pushvalue(L, -2);
  lua_pushstring(L, path.c_str());
  lua_pushcclosure(L, searchLuaText, 2);
  lua_rawseti(L, -2, 2);
  for (lua_Integer i = luaL_len(L, -1); i > 2; --i) {
    lua_pushnil(L);
    lua_rawseti(L, -2, i);
  }
  lua_pop(L, 2);
}

void compileAhead(const std::vector<std::string>& files) {
  lua_State* L = luaL_newstate();
  if (!L) return;
  for (const auto& file : files) {
    (void)loadModuleFile(L, file.c_str());  // (a file that does not compile fails when required)
    lua_settop(L, 0);
  }
  lua_close(L);
}

}  // namespace pitwall::sandbox
