#pragma once
// What a Lua world holds, in one list (bindings/world.cpp, openWorld): Lua's libraries as the
// sandbox leaves them, the console, require's path, the engine's types, the `pitwall` module and
// its parts, and the Lua half of the library. A new part of a world is one more line there.
//
// The private protocol between the C++ and the Lua library — the `pitwall._*` names, which
// scripts are not meant to use — is listed there too, and in docs/architecture.md.
#include <string>
#include <vector>

struct lua_State;

namespace pitwall {

class ScriptHost;

// Opens everything a new world holds, in order (ScriptHost's constructor, once).
void openWorld(ScriptHost& host);

// Puts `dirs` (each as DIR/?.lua and DIR/?/init.lua) before require's path: the world's library
// folders when it opens, a script's own folder when it is loaded (ScriptHost::loadFile).
void prependRequirePath(lua_State* L, const std::vector<std::string>& dirs);

// Compiles every file of the shipped library into this process's module cache
// (sandbox::compileAhead): worlds made afterwards, in this process or in a child forked from it,
// load the library's bytecode instead of parsing it.
void compileLibraryAhead();

}  // namespace pitwall
