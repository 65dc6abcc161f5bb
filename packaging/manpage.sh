#!/usr/bin/env bash
# packaging/manpage.sh PITWALL OUT.1: pitwall's man page, written by help2man (Debian's help2man)
# from the binary's own --help and --version, with a COMMANDS section holding every command's
# --help and the sections below. Run by the build (packaging/packaging.cmake).
set -euo pipefail
pitwall=$1 out=$2
include=$(mktemp)
trap 'rm -f "$include"' EXIT

# roff: a backslash is \e, a line starting with . or ' is text (\&)
roff() { sed -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"; }

{
  echo "[COMMANDS]"
  # bare `pitwall` lists the commands, two spaces in, one per line
  "$pitwall" | sed -n '/^Commands:/,/^$/p' | awk 'NF && $1 != "Commands:" {print $1}' |
    while read -r command; do
      echo ".SS \"pitwall $command\""
      echo ".nf"
      "$pitwall" "$command" --help | roff
      echo ".fi"
    done
  cat <<'SECTIONS'
[ENVIRONMENT]
.TP
.B PITWALL_DATA
The folder that holds pitwall's data (scripts/, examples/, web/, types/). By default it is
found beside the binary: ../share/pitwall for an installed pitwall, share/pitwall in a build
folder.
.TP
.B PITWALL_SCRIPTS
The folder of the Lua library (pitwall/core.lua, ...), instead of the data folder's scripts/.
.TP
.B PITWALL_VIEW_DIR
The race view's page, instead of the data folder's web/.
.TP
.B PITWALL_HISTORY
The REPL's history file (default ~/.pitwall_history).
.TP
.B PITWALL_INPUT_DIR
The folder run --gamepads watches for gamepads (evdev event nodes), instead of /dev/input.
.TP
.B PITWALL_WATCHDOG
Seconds the engine's loop may stand still in a real-time run before the watchdog sends every car
its stop from outside the loop (default 1; 0 turns the watchdog off).
.TP
.B PITWALL_PRINT_MODULE
The print module that track print and track verify load, instead of ../lib/pitwall/pitwall_print.so
beside the binary.
[FILES]
.TP
.I /usr/lib/pitwall/pitwall_print.so
The print module (cairo, librsvg): loaded by track print and track verify only.
.TP
.I /usr/share/pitwall/examples
Example race scripts, with a .luarc.json for the Lua language server.
.TP
.I /usr/share/pitwall/types
Definitions of the Lua API for the Lua language server (pitwall types DIR copies them).
.TP
.I /usr/share/doc/pitwall
The documentation: README.md and docs/.
[EXIT STATUS]
0 when the script or the command succeeded; 1 when a script failed or a test did not pass;
2 for a usage error (an unknown command or option, a missing script, a bad value); 130 after
Ctrl-C, SIGTERM or a hang-up; 141 when the output's reader went away (the cars stopped first).
Ctrl-Z stops the cars, then suspends the run.
SECTIONS
} >"$include"

# --version's first line only (the rest is about the machine that built the page); roff's own
# dash for the em dash, whatever the reader's locale.
help2man --locale=C.UTF-8 --no-info --no-discard-stderr --section=1 \
  --version-string="$("$pitwall" --version | head -1 | awk '{print $2}')" \
  --name="an automation engine for robot race cars, scripted in Lua" \
  --include="$include" --output="$out" "$pitwall"
sed -i 's/\xe2\x80\x94/\\(em/g; s/\xe2\x80\xa6/.../g' "$out"
