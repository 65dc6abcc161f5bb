#!/usr/bin/env bash
# The code page (issue 39, docs/classroom.md) as a lesson has it: `pitwall run --code FOLDER`,
# three cars in the shipped classroom race, the join code needed (here on loopback, behind a
# --view-host name as a proxy would serve it: the view asks for the code as off loopback). Two
# students in headless Chromium edit, save and test their own drivers; one's broken save is shown
# at its line and touches neither their car nor the other's; the teacher locks, starts, resets
# (tests/view/code_check.mjs). Then a third student's hostile requests reach no other desk's file
# or driver (tests/integration/code_hostile.py). Screenshots in ./view_test_artifacts/code-*.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"

install_checks view_code_check code_check.mjs
artifacts 'code-*.png'

lesson="$TMP/lesson"
"$PITWALL" run --code "$lesson" --view 127.0.0.1:0 --view-host classroom.test --cars 3 \
  --duration 600 > "$TMP/out" 2> "$TMP/err" &
pid=$!
if ! wait_for "$TMP/err" "^code: the teacher's page" 20; then
  fail "pitwall printed no teacher's page within 20 s"
  show_if_failed "pitwall's stderr" "$TMP/err"
  finish
fi
code=$(grep -oE '^view: join code [0-9]{6}' "$TMP/err" | head -1 | grep -oE '[0-9]{6}$')
port=$(grep -oE '^view: http://127\.0\.0\.1:[0-9]+/' "$TMP/err" | head -1 | grep -oE '[0-9]+/$' | tr -d /)
check "a join code is printed" 6 "${#code}"
teacher=$(grep -oE '#teacher=[0-9a-f]{32}' "$TMP/err" | head -1 | cut -d= -f2)
contains "the students' address is printed, with the join code" "/code?code=$code" "$(cat "$TMP/err")"
check "the teacher's key is 32 hex digits" 32 "${#teacher}"
for n in 1 2 3; do
  [ -f "$lesson/car-$n/driver.lua" ] && echo "ok: desk $n's driver file was made" ||
    fail "no $lesson/car-$n/driver.lua"
done
url="http://127.0.0.1:$port/"

timeout -k 5 240 node "$CHECK/code_check.mjs" "$url" "$code" "$teacher" "$ART" --timeout 40 \
  --chromium "$CHROMIUM"
check "code check exit status" 0 "$?"
for shot in code-editor code-error code-teacher; do
  [ -s "$ART/$shot.png" ] && echo "ok: screenshot $ART/$shot.png" || fail "no screenshot $ART/$shot.png"
done
# what the students saved is on disk, one file a save
[ -f "$lesson/car-1/history/1.lua" ] && echo "ok: Alice's first save is in her history" ||
  fail "no $lesson/car-1/history/1.lua"
contains "Bob's broken save is kept, not lost" "setSpeed(800 800)" "$(cat "$lesson/car-2/history/1.lua" 2>/dev/null)"

timeout -k 5 180 python3 "$SRC/tests/integration/code_hostile.py" "$port" "$code" "$teacher" "$lesson"
check "hostile requests exit status" 0 "$?"

kill -INT "$pid"
await_end "pitwall after Ctrl-C" 15 130
contains "the race the teacher started ran" "Race 1, 1 lap" "$(cat "$TMP/out")"
# (Bob's driver out after the reset is the one error the lesson has)
others=$(grep "error " "$TMP/err" | grep -v " error driver: driver driver.lua of car 2 (skull) is out" | head -5)
[ -z "$others" ] && echo "ok: no other error in the run's log" || fail "the run logged: $others"
show_if_failed "pitwall's stderr" "$TMP/err"
finish
