#include "engine/cli/repl_chunk.hpp"

namespace pitwall::cli {

namespace {

enum class Load { Ok, Incomplete, Invalid };

// Loads `code`; on success the function is pushed, otherwise the error goes to `error`.
Load load(lua_State* L, const std::string& code, std::string& error) {
  int status = luaL_loadbufferx(L, code.data(), code.size(), kChunkName, "t");  // text only
  if (status == LUA_OK) return Load::Ok;
  size_t len = 0;
  const char* msg = lua_tolstring(L, -1, &len);
  error = msg ? std::string(msg, len) : std::string("(syntax error without a message)");
  lua_pop(L, 1);
  // lua.c's test: a syntax error whose message ends in "<eof>" ran out of text.
  constexpr std::string_view kEof = "<eof>";
  bool atEof = status == LUA_ERRSYNTAX && error.size() >= kEof.size() &&
               error.compare(error.size() - kEof.size(), kEof.size(), kEof) == 0;
  return atEof ? Load::Incomplete : Load::Invalid;
}

}  // namespace

Chunk compileChunk(lua_State* L, std::string_view text) {
  Chunk chunk;
  if (!text.empty() && text.front() == '=') {  // `=expr`: always an expression
    switch (load(L, "return " + std::string(text.substr(1)), chunk.error)) {
      case Load::Ok:
        chunk.status = ChunkStatus::Ready;
        break;
      case Load::Incomplete:
        chunk.status = ChunkStatus::Incomplete;
        break;
      case Load::Invalid:
        chunk.status = ChunkStatus::Invalid;
        break;
    }
    return chunk;
  }
  // The return trick: an expression shows its value; a call shows what it returned.
  std::string asExpression;
  Load expression = load(L, "return " + std::string(text), asExpression);
  if (expression == Load::Ok) {
    chunk.status = ChunkStatus::Ready;
    return chunk;
  }
  Load statement = load(L, std::string(text), chunk.error);
  if (statement == Load::Ok) {
    chunk.error.clear();
    chunk.status = ChunkStatus::Ready;
  } else if (statement == Load::Incomplete || expression == Load::Incomplete) {
    // `1 +` is no statement but an unfinished expression: wait for the rest of it.
    chunk.status = ChunkStatus::Incomplete;
    if (statement != Load::Incomplete) chunk.error = asExpression;
  } else {
    chunk.status = ChunkStatus::Invalid;  // the statement's error, as lua.c reports it
  }
  return chunk;
}

}  // namespace pitwall::cli
