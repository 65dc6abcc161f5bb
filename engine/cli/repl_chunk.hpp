#pragma once
// How the REPL turns what was typed into a Lua function, the way lua.c and luaprompt do it:
// `=expr` is `return expr`; any other text is first tried as `return <text>` (so an expression
// prints its value) and then as a statement; a syntax error at the very end of the text
// (`… near <eof>`) means the chunk is not finished yet and the prompt asks for another line.
#include <lua.hpp>

#include <string>
#include <string_view>

namespace pitwall::cli {

enum class ChunkStatus {
  Ready,       // compiled: the function is on top of L's stack
  Incomplete,  // more lines may complete it: nothing pushed
  Invalid,     // a syntax error no further line can fix: nothing pushed
};

struct Chunk {
  ChunkStatus status = ChunkStatus::Invalid;
  std::string error;  // Invalid and Incomplete: the syntax error ("stdin:1: … near <eof>")
};

// The name errors give the typed code: "stdin:1: …".
inline constexpr const char* kChunkName = "=stdin";

// Compiles `text` (one line, or the lines of a multi-line chunk joined by '\n') in L.
Chunk compileChunk(lua_State* L, std::string_view text);

}  // namespace pitwall::cli
