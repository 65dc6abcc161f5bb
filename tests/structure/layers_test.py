#!/usr/bin/env python3
"""The floors of docs/architecture.md, checked on every #include of engine/ and bindings/.

A file may include only floors below its own (peers on one floor do not include each other), and
nothing below bindings/ includes Lua. Usage: tests/structure/layers_test.py SOURCE_ROOT [--self-test].
Fails naming the file, the line and the floor it reaches.
"""
import re
import sys

import structure_check

# Lower first. Peers share a rank: they may not include each other.
FLOORS = {
    "engine/core": 0,
    "engine/protocol": 1,
    "engine/sim": 2,
    "engine/transport": 3,  # SimLink carries frames to the simulator's cars
    "engine/vehicles": 4,
    "engine/fleet": 5,
    "engine/record": 6,
    "engine/mqtt": 6,
    "engine/drive": 6,  # human seats and the devices that hold them: above the fleet
    "engine/view": 7,  # the view shows the seats and its /drive page holds them
    "engine/print": 6,  # printing pieces and reading them back: the sim's geometry, drawn
    "engine/laps": 6,  # laps as traces (tracker, trace, compare): the car model's frames, drawn
    "engine/league": 6,  # a league's heats, points and report: plain data, no cars
    "engine/classroom": 6,  # the code page's desks, files and credentials: plain files, no cars
    "engine/standings": 7,  # every race's and league's results kept (SQLite): a league's points
    "bindings": 8,
    "engine/cli": 9,
}
LUA_FROM = FLOORS["bindings"]  # the lowest floor that may know Lua
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')
LUA_HEADERS = {"lua.hpp", "lua.h", "lualib.h", "lauxlib.h"}


def floor_of(path):
    for floor in sorted(FLOORS, key=len, reverse=True):
        if path == floor or path.startswith(floor + "/"):
            return floor
    return None


def violations(files):
    """files: {relative path: text}. Yields one sentence per include that goes up or sideways."""
    for path, text in sorted(files.items()):
        here = floor_of(path)
        if here is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target = m.group(1)
            if target in LUA_HEADERS and FLOORS[here] < LUA_FROM:
                yield f"{path}:{number}: includes <{target}>: nothing below bindings/ knows Lua"
                continue
            there = floor_of(target)
            if there is None or there == here:
                continue
            if FLOORS[there] >= FLOORS[here]:
                kind = "a peer" if FLOORS[there] == FLOORS[here] else "a floor above"
                yield (f"{path}:{number}: {here} includes {target}, {kind} "
                       f"({there}); a layer uses only layers below it (docs/architecture.md)")


def self_test():
    bad = {
        "engine/vehicles/x.cpp": '#include "engine/fleet/fleet.hpp"\n',
        "engine/mqtt/y.cpp": '#include "engine/view/feed.hpp"\n',
        "engine/transport/z.cpp": "#include <lua.hpp>\n",
    }
    good = {
        "engine/fleet/f.cpp": '#include "engine/vehicles/anki_car.hpp"\n#include <vector>\n',
        "engine/cli/c.cpp": '#include "bindings/script_host.hpp"\n#include <lua.hpp>\n',
        "bindings/b.cpp": "#include <lua.hpp>\n",
    }
    found = list(violations(bad))
    assert len(found) == 3, found
    assert not list(violations(good)), list(violations(good))


if __name__ == "__main__":
    sys.exit(structure_check.run("layers", "includes out of order", self_test, violations))
