#!/usr/bin/env python3
"""The binding layer's one idioms (issue 37, docs/architecture.md "Lua"), checked on the code of
engine/ and bindings/ (comments left out):

- one file calls into Lua protected: lua_pcall (and luaL_dostring / luaL_dofile, which expand to
  it) appear only in bindings/protected_call.hpp, whose lua::protectedCall every call path of the
  engine builds on. (lua_pcallk in bindings/interrupt.cpp is the script's own xpcall: Lua calling
  Lua.)
- only the object idiom (bindings/lua_object.hpp/.cpp) makes metatables and userdata and reads
  userdata back (lua::registerType, newBox, check<T>, test<T>); bindings/metatables.cpp, which
  locks them, gives each its face.

Usage: bindings_test.py SOURCE_ROOT. A self-test runs first, so the check cannot pass by finding
nothing. Fails naming the file, the line and the rule.
"""
import re
import sys

import structure_check

IDIOM = {"bindings/lua_object.hpp", "bindings/lua_object.cpp"}
RULES = [
    (re.compile(r"\b(lua_pcall|luaL_dostring|luaL_dofile)\s*\("),
     {"bindings/protected_call.hpp"},
     "calls into Lua outside lua::protectedCall (bindings/protected_call.hpp): use the world's "
     "call path (ScriptHost::call, callCapturing, callInteractive)"),
    # bindings/metatables.cpp gives each locked metatable its face (a table with a metatable)
    (re.compile(r"\b(luaL_newmetatable|lua_newuserdatauv|lua_newuserdata|luaL_setmetatable|"
                r"lua_setmetatable)\s*\("),
     IDIOM | {"bindings/metatables.cpp"},
     "makes a metatable or a userdata outside the object idiom: declare a lua::TypeSpec and use "
     "lua::registerType and lua::newBox (bindings/lua_object.hpp)"),
    (re.compile(r"\b(luaL_checkudata|luaL_testudata)\s*\("),
     IDIOM,
     "reads a userdata outside the object idiom: use lua::check<T> or lua::test<T> with the "
     "type's TypeSpec (one wording for a wrong value)"),
]

LINE_COMMENT = re.compile(r"//.*$")
BLOCK_COMMENT = re.compile(r"/\*.*?\*/", re.S)
STRING = re.compile(r'"(?:\\.|[^"\\])*"')


def code_lines(text):
    """The lines of C++ text with comments and string literals blanked (line numbers kept)."""
    text = BLOCK_COMMENT.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    for line in text.splitlines():
        yield LINE_COMMENT.sub("", STRING.sub('""', line))


def violations(files):
    """files: {relative path: text}. Yields one sentence per use that breaks a rule."""
    for path, text in sorted(files.items()):
        for number, line in enumerate(code_lines(text), 1):
            for pattern, allowed, why in RULES:
                m = pattern.search(line)
                if m and path not in allowed:
                    yield f"{path}:{number}: {m.group(1)}: {why}"


def self_test():
    bad = {
        "bindings/x.cpp": "int f(lua_State* L) { return lua_pcall(L, 0, 0, 0); }\n",
        "engine/cli/y.cpp": "void g(lua_State* L) {\n  luaL_dostring(L, \"x = 1\");\n}\n",
        "bindings/seat.cpp": "  luaL_newmetatable(L, kSeat);\n",
        "bindings/timer.cpp": "  auto* h = static_cast<int*>(lua_newuserdatauv(L, 4, 0));\n",
        "bindings/robot.cpp": "  auto* r = luaL_testudata(L, 1, kRobot);\n",
    }
    good = {
        "bindings/protected_call.hpp": "  status = lua_pcall(L, nargs, nresults, handler);\n",
        "bindings/interrupt.cpp": "  return lua_pcallk(L, n, LUA_MULTRET, 2, 0, k);\n",
        "bindings/z.cpp": "// lua_pcall(L, 0, 0, 0) in a comment\nconst char* s = \"lua_pcall(\";\n",
        "bindings/lua_object.cpp": "  void* p = lua_newuserdatauv(L, size, 1);\n",
    }
    found = list(violations(bad))
    assert len(found) == 5, found
    assert [f.split(":")[0] for f in found] == sorted(bad), found
    assert not list(violations(good)), list(violations(good))


if __name__ == "__main__":
    sys.exit(structure_check.run("bindings", "uses against the binding idioms", self_test, violations))
