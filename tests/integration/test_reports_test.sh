# pitwall test for daily use and for CI (docs/testing.md "Running scenarios"): --filter by a part of the
# name, a glob or a tag, --list, -j with results in a stable order and a crash that is one
# failed scenario, JUnit XML read back by Python's xml (counts, names, file and line of each
# failure), TAP 14, a failed expectation shown at the test's line without the library's frames
# (they come with --verbose), a stuck scenario saying where each task waits, --seed random
# printing the seed that replays a failure.
source "$(dirname "$0")/lib.sh"

S="$TMP/suite"
mkdir -p "$S/sub"
cat > "$S/alpha_test.lua" <<'LUA'
-- tags: fast smoke
expect.eq(1 + 1, 2)
LUA
cat > "$S/beta_test.lua" <<'LUA'
-- Compares a speed.
-- tags: race
local sim = require "pitwall.sim"
local car = sim.addCar {}
print("beta starts")
sim.run(1)
expect.eq(car.speed, 123, "speed")
LUA
cat > "$S/sub/gamma_test.lua" <<'LUA'
-- tags: race, slow
local function deeper() error("gamma broke") end
local function helper() deeper() end
helper()
LUA
cat > "$S/stuck_test.lua" <<'LUA'
local sim = require "pitwall.sim"
pitwall.spawn(function()
  sim.runUntil(function() return false end, 1e9)
end)
pitwall.sleep(1e9)
LUA
cat > "$S/crash_test.lua" <<'LUA'
-- Spins until the test kills its process (a crash), once it has said so on the fifo READY.
local ready = os.getenv("READY")
if ready then
  print("the last words before the crash")
  local f = assert(io.open(ready, "w"))
  f:write("spinning\n")
  f:close()
  while true do end
end
error("not crashed")
LUA
cat > "$S/random_test.lua" <<'LUA'
expect.lt(math.random(1000), 0, "a random number")
LUA

# --list and --filter
out=$($PITWALL test "$S" --list); rc=$?
check "--list: exit status" 0 "$rc"
check "--list: every scenario, in name order, with its tags" \
  "$S/alpha_test.lua  [fast smoke]|$S/beta_test.lua  [race]|$S/crash_test.lua|$S/random_test.lua|$S/stuck_test.lua|$S/sub/gamma_test.lua  [race slow]" \
  "$(echo "$out" | paste -sd'|')"
check "--filter by tag" "$S/beta_test.lua  [race]|$S/sub/gamma_test.lua  [race slow]" \
  "$($PITWALL test "$S" --list --filter race | paste -sd'|')"
check "--filter by a part of the name" "$S/alpha_test.lua  [fast smoke]" \
  "$($PITWALL test "$S" --list --filter alph | paste -sd'|')"
check "--filter by glob, given twice" "$S/alpha_test.lua  [fast smoke]|$S/sub/gamma_test.lua  [race slow]" \
  "$($PITWALL test "$S" --list --filter 'g*_test' --filter smoke | paste -sd'|')"
err=$($PITWALL test "$S" --filter smokr 2>&1); rc=$?
check "--filter matching nothing: exit status" 2 "$rc"
contains "--filter matching nothing: named, with the nearest" \
  "--filter smokr matches none of the 6 scenarios; did you mean smoke?" "$err"
err=$($PITWALL test "$S" --filter zzz --filter raec 2>&1)
contains "two filters matching nothing: the nearest of either" \
  "--filter zzz, raec match none of the 6 scenarios; did you mean race (for raec)?" "$err"
err=$($PITWALL test "$S" --filter "" 2>&1); rc=$?
check "an empty --filter: exit status" 2 "$rc"
contains "an empty --filter: said" "an empty pattern matches every scenario" "$err"

# one failed expectation: the test's line and the values; no library frames unless --verbose
out=$($PITWALL test "$S/beta_test.lua" 2>&1); rc=$?
check "a failing scenario: exit status" 1 "$rc"
contains "the test's line and the values compared" "beta_test.lua:7: speed: expected 123, got 0" "$out"
contains "what it printed comes first" "beta starts" "$out"
case "$out" in *pitwall/test.lua*|*"[C]"*) fail "library or C frames without --verbose: $out" ;; *) echo "ok: no library frames" ;; esac
contains "how to replay it" "seed 1: pitwall test $S/beta_test.lua --seed 1 replays it" "$out"
out=$($PITWALL test "$S/beta_test.lua" --verbose 2>&1)
contains "--verbose: the library's frames" "pitwall/test.lua" "$out"
out=$($PITWALL test "$S/sub/gamma_test.lua" 2>&1)
contains "an error in the test's own functions: their frames" "gamma_test.lua:3: in local 'helper'" "$out"

# a stuck scenario says where each of its tasks waits, and when
out=$($PITWALL test "$S/stuck_test.lua" --timeout 5 2>&1)
contains "stuck: the timeout" "still running after 5 s of virtual time" "$out"
contains "stuck: the virtual time it was stopped at" "at 5.0 s of virtual time:" "$out"
contains "stuck: the main chunk's line" "main chunk waiting at $S/stuck_test.lua:5 (in sleep)" "$out"
contains "stuck: the task's line, inside the library's wait" "stuck_test.lua:3 (in runUntil)" "$out"
contains "stuck: the replay keeps the run's options" "pitwall test $S/stuck_test.lua --seed 1 --timeout 5 replays it" "$out"

# -j: the same report in the same order as one at a time
one=$($PITWALL test "$S" -j 1 --timeout 5 2>&1 | sed 's/ in [0-9]* ms)/)/')
many=$($PITWALL test "$S" -j 4 --timeout 5 2>&1 | sed 's/ in [0-9]* ms)/)/')
check "-j 4 reports as -j 1 does, in the same order" "$one" "$many"
check "-j: closing line" "1 passed, 5 failed" "$(echo "$many" | tail -1)"

# a scenario whose process dies is one failed scenario; the run goes on
mkfifo "$TMP/ready"
READY="$TMP/ready" $PITWALL test "$S" --filter crash --filter alpha --filter random -j 1 \
  --budget 0 >"$TMP/crash.out" 2>&1 &
RUN_PID=$!
# Opened read-write, the fifo does not block the open itself: a run that never gets to write
# (it failed to start) makes the read time out and the test fail, not hang until ctest kills it.
exec 5<>"$TMP/ready"
read -r -t 20 line <&5
exec 5<&-
check "the crashing scenario spins" "spinning" "$line"
child=$(pgrep -P "$RUN_PID")
kill -SEGV "$child"
wait "$RUN_PID"
check "a crash: exit status" 1 "$?"
crash=$(cat "$TMP/crash.out")
contains "the crash is reported with its signal" "FAIL  $S/crash_test.lua (0.0 s simulated" "$crash"
contains "…and its signal" "the scenario's process crashed: signal 11 (Segmentation fault)" "$crash"
contains "the scenarios before and after it ran" "1 passed, 2 failed" "$(echo "$crash" | tail -1)"
contains "what it printed just before the crash is kept" "the last words before the crash" "$crash"

# JUnit XML, as CI systems read it
$PITWALL test "$S" -j 2 --timeout 5 --junit "$TMP/out.xml" >/dev/null 2>&1
rc=$?
check "--junit: exit status is the run's" 1 "$rc"
junit=$(python3 - "$TMP/out.xml" "$S" <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
assert root.tag == "testsuites", root.tag
suite = root.find("testsuite")
cases = suite.findall("testcase")
print("counts", suite.get("tests"), suite.get("failures"), suite.get("errors"), suite.get("skipped"),
      root.get("tests"), len(cases))
for c in cases:
    failure = c.find("failure")
    error = c.find("error")
    kind = "failure" if failure is not None else "error" if error is not None else "passed"
    float(c.get("time"))
    line = c.get("line") or "-"
    print(c.get("classname"), c.get("name"), kind, c.get("file").replace(sys.argv[2], "S"), line)
beta = [c for c in cases if c.get("name") == "beta_test"][0]
print("message", beta.find("failure").get("message").replace(sys.argv[2], "S"))
print("out", beta.find("system-out").text.strip())
PY
)
contains "JUnit: counts (6 tests, 2 failed expectations, 3 errors)" "counts 6 2 3 0 6 6" "$junit"
contains "JUnit: a passing case" "alpha_test passed S/alpha_test.lua -" "$junit"
contains "JUnit: a failed expectation with file and line" "beta_test failure S/beta_test.lua 7" "$junit"
contains "JUnit: an error at its line in the test" "gamma_test error S/sub/gamma_test.lua 2" "$junit"
contains "JUnit: the stuck one is an error at the line its main chunk waits at" "stuck_test error S/stuck_test.lua 5" "$junit"
contains "JUnit: the crash is an error" "crash_test error" "$junit"
contains "JUnit: the failure's message" "message S/beta_test.lua:7: speed: expected 123, got 0" "$junit"
contains "JUnit: what it printed" "out beta starts" "$junit"
# hostile text in what a scenario prints and raises: the XML stays well-formed, TAP one line each
mkdir -p "$TMP/hostile"
cat > "$TMP/hostile/hostile_test.lua" <<'LUA'
print("nul\0 esc\27[31m <![CDATA[ ]]> <&>\"' \255\254 vitesse\r\n \u{FFFE}\u{FFFF}")
for i = 1, 20000 do io.write("flood ", i, "\n") end
error("bad \0 <xml attr=\"x\"> & ]]> \255 \1\2\3", 0)
LUA
$PITWALL test "$TMP/hostile" --junit "$TMP/hostile.xml" >"$TMP/hostile.out" 2>&1
hostile=$(python3 - "$TMP/hostile.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
case = ET.parse(sys.argv[1]).getroot().find("testsuite/testcase")
out = case.find("system-out").text
print(case.find("error").get("message"))
print(out.count("flood "), "<![CDATA[ ]]>" in out, "\\x00" in out)
PY
)
contains "hostile text: the JUnit file parses, the message escaped" 'bad \x00 <xml attr="x"> & ]]> \xff \x01\x02\x03' "$hostile"
contains "hostile text: every line of a flood kept, the rest escaped" "20000 True True" "$hostile"
check "hostile text: the failure's report has no control byte (what it printed is its own)" "0" \
  "$(grep -a '^      ' "$TMP/hostile.out" | tr -d '\n' | LC_ALL=C grep -ac '[[:cntrl:]]')"
contains "hostile text: the whole message, past a NUL byte" 'bad \x00 <xml attr="x"> & ]]> \xff' \
  "$(cat "$TMP/hostile.out")"
$PITWALL test "$TMP/hostile" --tap >"$TMP/hostile.tap" 2>&1
check "hostile text: every TAP line is a comment, a test point, the plan or YAML" "" \
  "$(grep -vE '^(# |ok |not ok |TAP version |1\.\.|  )' "$TMP/hostile.tap")"

# the ways a scenario may end otherwise: os.exit fails it; an error object is shown by __tostring;
# a path with '#' and spaces stays one TAP description and one shell word in the replay
mkdir -p "$TMP/odd #1 dir"
cat > "$TMP/odd #1 dir/exit_test.lua" <<'LUA'
pitwall.after(0.5, function() os.exit(0) end)
pitwall.sleep(1)
LUA
cat > "$TMP/odd #1 dir/object_test.lua" <<'LUA'
error(setmetatable({}, { __tostring = function() return "a custom error object" end }))
LUA
odd=$($PITWALL test "$TMP/odd #1 dir" 2>&1); rc=$?
check "os.exit and an error object: exit status" 1 "$rc"
contains "os.exit in a scenario fails it" "the scenario called os.exit(0)" "$odd"
contains "an error object is shown by its __tostring" "a custom error object" "$odd"
contains "the replay quotes the path" "pitwall test '$TMP/odd #1 dir/exit_test.lua' --seed 1 replays it" "$odd"
tap=$($PITWALL test "$TMP/odd #1 dir" --tap 2>&1)
contains "TAP: a '#' in the description is escaped" "not ok 1 - $TMP/odd \#1 dir/exit_test.lua" "$tap"

err=$($PITWALL test "$S/alpha_test.lua" --junit "$TMP/no/such/dir/out.xml" 2>&1); rc=$?
check "--junit into a missing folder: exit status" 2 "$rc"
contains "--junit into a missing folder: said before running" "cannot write the file" "$err"

# TAP 14
tap=$($PITWALL test "$S" --filter race --tap 2>&1)
check "TAP: version and plan first" "TAP version 14|1..2" "$(echo "$tap" | head -2 | paste -sd'|')"
contains "TAP: the failing point" "not ok 1 - $S/beta_test.lua" "$tap"
contains "TAP: its YAML block" "  at:
    file: \"$S/beta_test.lua\"
    line: 7" "$tap"
contains "TAP: output as comments" "# beta starts" "$tap"

# --seed random: each failure prints the seed that replays it exactly
out=$($PITWALL test "$S/random_test.lua" --seed random 2>&1)
seed=$(echo "$out" | sed -n 's/.*seed \([0-9]*\): pitwall test.*/\1/p')
[ -n "$seed" ] && echo "ok: --seed random prints the seed ($seed)" || fail "no seed printed: $out"
first=$(echo "$out" | grep -o 'expected [0-9]* < 0')
again=$($PITWALL test "$S/random_test.lua" --seed "$seed" 2>&1 | grep -o 'expected [0-9]* < 0')
check "the printed seed replays the failure exactly" "$first" "$again"
err=$($PITWALL test "$S" --seed often 2>&1); rc=$?
check "a bad --seed: exit status" 2 "$rc"
contains "a bad --seed: named" "--seed often: expected a whole number" "$err"

finish
