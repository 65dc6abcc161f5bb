# pitwall repl: with piped input (no terminal: no prompt, values on stdout, errors on stderr), then
# the interactive prompt through a real pseudo-terminal (repl_pty_test.py, python3-pexpect).
source "$(dirname "$0")/lib.sh"

out=$(printf '=1+1\nx = 20\n=x + 1\nfunction f()\n  return 5\nend\nf()\n' | $PITWALL repl 2>"$TMP/err")
rc=$?
check "piped input: exit status at the end of input" 0 "$rc"
check "piped input: the values, one per line, nothing else" $'2\n21\n5' "$out"

out=$(printf 'error("boom")\n:nope\n=cars[1].number\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "piped input with a failing chunk: exit status" 1 "$rc"
check "piped input with a failing chunk: the rest still runs" "1" "$out"
contains "the error goes to stderr" "stdin:1: boom" "$(cat "$TMP/err")"
contains "an unknown command is named" "unknown command :nope" "$(cat "$TMP/err")"

# Before any drive the cars stand where the grid put them (docs/simulator.md), not at 0.
out=$(printf '=cars[1].offset\n=cars[4].offset\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "offsets before any drive: exit status" 0 "$rc"
check "offsets before any drive: the grid's outer lanes" $'-68.0\n68.0' "$out"

# A chunk that waits holds the next line until it is over.
out=$(printf 'pitwall.sleep(0.5)\n=pitwall.now() >= 0.5\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "piped input with a sleep: exit status" 0 "$rc"
check "piped input with a sleep: the next line ran after it" "true" "$out"
out=$(printf 'pitwall.sleep(-1)\n=1\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "a chunk whose sleep fails: exit status" 1 "$rc"
contains "a chunk whose sleep fails: its error" "pitwall.sleep" "$(cat "$TMP/err")"

# help, piped: nothing is cut (no terminal), every method is there
out=$(printf 'help(cars[1])\nhelp(pitwall._raise)\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "help piped: exit status" 0 "$rc"
contains "help piped: a method with its parameters" "setSpeed(speed, accel?, respectLimit?)" "$out"
contains "help piped: the whole description" "needs the car to be moving: refused while it stands, with what to do." "$out"
contains "help piped: an internal function gets one line" "help: no help for function: [C]" "$out"
echo 'print("script sees help: " .. tostring(help))' > "$TMP/sees.lua"
out=$($PITWALL run "$TMP/sees.lua" --fast --duration 1 2>&1)
contains "a script does not see help" "script sees help: nil" "$out"

out=$(printf 'function f(\n' | $PITWALL repl 2>"$TMP/err"); rc=$?
check "an unfinished chunk at the end of input: exit status" 1 "$rc"
contains "an unfinished chunk at the end of input: its syntax error" "<eof>" "$(cat "$TMP/err")"

# A regular file and /dev/null (epoll cannot wait for either).
printf '=6 * 7\n:quit\n=0\n' > "$TMP/input.lua"
out=$($PITWALL repl < "$TMP/input.lua" 2>/dev/null); rc=$?
check "input from a file: exit status" 0 "$rc"
check "input from a file: the value, and nothing after :quit" "42" "$out"
out=$($PITWALL repl < /dev/null 2>/dev/null); rc=$?
check "no input: exit status" 0 "$rc"
check "no input: no output" "" "$out"

out=$(printf '=1\n' | $PITWALL repl --track nowhere 2>&1); rc=$?
check "unknown track: exit status" 2 "$rc"
contains "unknown track is named" "nowhere" "$out"

finish
if [ ! -x /usr/bin/python3 ]; then
  echo "skip: the terminal half needs /usr/bin/python3 with python3-pexpect (./dev test installs it)"
  exit 77
fi
/usr/bin/python3 "$(dirname "$0")/repl_pty_test.py" "$PITWALL"
