#include "bindings/protected_call.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "bindings/misspelled_method.hpp"

namespace pitwall::lua {

namespace {
void abortOnUnbalanced(const char* where, int expected, int found) {
  std::fprintf(stderr,
               "pitwall: the Lua stack is unbalanced after %s: its top is %d, expected %d (a "
               "binding pushed or popped one value too many)\n",
               where, found, expected);
  std::abort();
}
StackFailure g_stackFailure = abortOnUnbalanced;  // debug builds' aid, set by tests only
}  // namespace

StackFailure setStackFailure(StackFailure failure) {
  StackFailure before = g_stackFailure;
  g_stackFailure = failure ? failure : abortOnUnbalanced;
  return before;
}

void stackUnbalanced(const char* where, int expected, int found) {
  g_stackFailure(where, expected, found);
}

const char* errorText(lua_State* L, int idx) {
  idx = lua_absindex(L, idx);
  std::size_t len = 0;
  const char* text = lua_tolstring(L, idx, &len);
  if (!text || std::strlen(text) == len) return text;
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (std::size_t i = 0; i < len; ++i) {
    if (text[i] == '\0')
      luaL_addstring(&b, "\\x00");
    else
      luaL_addchar(&b, text[i]);
  }
  luaL_pushresult(&b);
  lua_replace(L, idx);
  return lua_tostring(L, idx);
}

namespace {
int toText(lua_State* L) {
  luaL_tolstring(L, 1, nullptr);
  return 1;
}
}  // namespace

const char* errorObjectText(lua_State* L, int idx, std::chrono::milliseconds budget) {
  idx = lua_absindex(L, idx);
  if (luaL_getmetafield(L, idx, "__tostring") != LUA_TNIL) {
    lua_pop(L, 1);
    lua_pushcfunction(L, toText);
    lua_pushvalue(L, idx);
    if (protectedCall(L, 1, 1, 0, interrupt::Kind::Callback, budget) == LUA_OK &&
        lua_type(L, -1) == LUA_TSTRING)
      return errorText(L, -1);
    lua_pop(L, 1);
  }
  return lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, idx));
}

int traceback(lua_State* L) {
  const char* msg = errorText(L, 1);
  if (!msg) {
    if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) return 1;
    msg = lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  } else if (auto explained = explainMissingName(L, 1, msg)) {
    msg = lua_pushlstring(L, explained->data(), explained->size());
  }
  pushTraceback(L, L, msg, 1);
  return 1;
}

namespace {
const Frames kDefaultFrames;
const char kFramesKey = 0;  // its address: the registry key of a world's Frames
}  // namespace

void setFrames(lua_State* L, const Frames* frames) {
  if (frames)
    lua_pushlightuserdata(L, const_cast<Frames*>(frames));
  else
    lua_pushnil(L);
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kFramesKey);
}

const Frames& framesOf(lua_State* L) {
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kFramesKey);
  const auto* frames = static_cast<const Frames*>(lua_touserdata(L, -1));
  lua_pop(L, 1);
  return frames ? *frames : kDefaultFrames;
}

void pushUserWhere(lua_State* L) {
  lua_Debug ar;
  for (int level = 1; lua_getstack(L, level, &ar); ++level) {
    if (!lua_getinfo(L, "Sl", &ar) || ar.currentline <= 0) continue;  // C functions
    if (isLibrarySource(L, ar.source)) continue;
    lua_pushfstring(L, "%s:%d: ", ar.short_src, ar.currentline);
    return;
  }
  luaL_where(L, 1);  // only the library on the stack (an engine call into it): its own line
}

bool isLibrarySource(lua_State* L, const char* source) {
  return std::string_view(source).starts_with(framesOf(L).libraryChunks);
}

void pushTraceback(lua_State* L, lua_State* L1, const char* msg, int level) {
  if (framesOf(L).libraryFrames) return luaL_traceback(L, L1, msg, level);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  if (msg) {
    luaL_addstring(&b, msg);
    luaL_addchar(&b, '\n');
  }
  luaL_addstring(&b, "stack traceback:");
  lua_Debug ar;
  int listed = 0;
  for (; lua_getstack(L1, level, &ar); ++level) {
    if (!lua_getinfo(L1, "Slnt", &ar)) continue;
    if (ar.currentline <= 0 || isLibrarySource(L, ar.source)) continue;
    if (++listed > 20) {
      luaL_addstring(&b, "\n\t...");
      break;
    }
    lua_pushfstring(L, "\n\t%s:%d: in ", ar.short_src, ar.currentline);
    luaL_addvalue(&b);
    if (*ar.what == 'm')
      lua_pushliteral(L, "main chunk");
    else if (*ar.namewhat)
      lua_pushfstring(L, "%s '%s'", ar.namewhat, ar.name);
    else
      lua_pushfstring(L, "function <%s:%d>", ar.short_src, ar.linedefined);
    luaL_addvalue(&b);
    if (ar.istailcall) luaL_addstring(&b, "\n\t(...tail calls...)");
  }
  luaL_pushresult(&b);
}

}  // namespace pitwall::lua
