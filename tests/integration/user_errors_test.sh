# Errors that point at the user (issue 18), from the command line: a missing or broken script is
# refused before any car is connected (so at once, even with --ble or --mqtt, which would scan or
# reach a broker first), and messages name files relative to the current folder.
source "$(dirname "$0")/lib.sh"

# A missing script: exit status 2 at once, naming the file, before BlueZ or a broker is asked.
# (timeout: a connection attempt would take the scan's or the broker's time; the check takes none)
for source in "--ble" "--mqtt mqtt://192.0.2.1:1883" "--fast"; do
  # shellcheck disable=SC2086
  err=$(cd "$TMP" && timeout 10 "$PITWALL" run nosuch.lua $source 2>&1 >/dev/null); rc=$?
  check "missing script with $source: exit status" 2 "$rc"
  check "missing script with $source: the one line says which file" \
    "pitwall run: cannot open nosuch.lua: no such file" "$err"
done

# A script that does not compile: status 1, file and line, before any connection either.
printf 'local x = \nfor\n' > "$TMP/broken.lua"
err=$(cd "$TMP" && timeout 10 "$PITWALL" run broken.lua --ble 2>&1 >/dev/null); rc=$?
check "broken script with --ble: exit status" 1 "$rc"
contains "broken script with --ble: file and line" "pitwall run: broken.lua:2:" "$err"
case "$err" in *[Bb]lue[Zz]*|*scan*|*adapter*) fail "no connection was attempted: $err" ;; esac

# pitwall test and pitwall replay --script refuse a missing path the same way.
err=$(timeout 10 "$PITWALL" test "$TMP/nosuch_test.lua" 2>&1 >/dev/null); rc=$?
check "pitwall test on a missing path: exit status" 2 "$rc"
contains "pitwall test names it" "nosuch_test.lua" "$err"
printf '{}\n' > "$TMP/r.jsonl"
err=$(cd "$TMP" && timeout 10 "$PITWALL" replay r.jsonl --script nosuch.lua 2>&1 >/dev/null); rc=$?
check "replay --script missing: exit status" 2 "$rc"
check "replay --script missing: named" "pitwall replay: cannot open nosuch.lua: no such file" "$err"

# Paths relative to the current folder: a script given by its absolute path is named
# sub/oops.lua:2: in its error, and so is a module it requires from its folder.
mkdir -p "$TMP/sub"
printf 'local m = require "helper"\nm.go()\n' > "$TMP/sub/oops.lua"
printf 'return { go = function() error("broken helper") end }\n' > "$TMP/sub/helper.lua"
err=$(cd "$TMP" && "$PITWALL" run "$TMP/sub/oops.lua" --fast 2>&1 >/dev/null); rc=$?
check "a failing script: exit status" 1 "$rc"
contains "the module is named relative to the current folder" "sub/helper.lua:1: broken helper" "$err"
contains "the script is named relative to the current folder" "sub/oops.lua:2:" "$err"
case "$err" in *"$TMP/sub"*) fail "an absolute path in: $err" ;; *) echo "ok: no absolute path" ;; esac

# A library error names the script's line, not scripts/pitwall/: the first line of the report.
printf 'local race = require "pitwall.race"\n\nrace.laps { lapz = 3 }\n' > "$TMP/user.lua"
err=$(cd "$TMP" && "$PITWALL" run user.lua --fast 2>&1 >/dev/null); rc=$?
check "a library error: exit status" 1 "$rc"
first=$(printf '%s\n' "$err" | grep -m1 'error in')
contains "the script's line is blamed, with the suggestion" \
  "user.lua:3: race.laps: unknown option lapz; did you mean laps?" "$first"
case "$first" in *scripts/pitwall*) fail "the library is blamed: $first" ;; esac

# A misspelled method, as the run reports it.
printf 'local car = pitwall.cars()[1]\ncar:setSped(300)\n' > "$TMP/typo.lua"
err=$(cd "$TMP" && "$PITWALL" run typo.lua --fast --cars 1 2>&1 >/dev/null); rc=$?
check "a misspelled method: exit status" 1 "$rc"
contains "a misspelled method: the line and the suggestion" \
  "typo.lua:2: car has no method setSped; did you mean setSpeed?" "$err"

# The other typos (issue 35), as a run and the REPL report them: a sentence naming what exists.
cars="1 groundshock, 2 skull, 3 thermo, 4 nuke"
printf 'local car = pitwall.car("groundshok")\ncar:setSpeed(500)\n' > "$TMP/car.lua"
err=$(cd "$TMP" && "$PITWALL" run car.lua --fast 2>&1 >/dev/null); rc=$?
check "a misspelled car: exit status" 1 "$rc"
contains "a misspelled car: the cars and the nearest" \
  "car.lua:1: pitwall.car: no car named 'groundshok'; did you mean groundshock? The cars are $cars" "$err"
printf 'pitwall.car(9):setSpeed(500)\n' > "$TMP/nine.lua"
err=$(cd "$TMP" && "$PITWALL" run nine.lua --fast 2>&1 >/dev/null)
contains "a car number that is not there: the cars" "nine.lua:1: pitwall.car: no car 9; the cars are $cars" "$err"
printf 'pitwall.spwan(function() end)\n' > "$TMP/spwan.lua"
err=$(cd "$TMP" && "$PITWALL" run spwan.lua --fast 2>&1 >/dev/null); rc=$?
check "a misspelled library function: exit status" 1 "$rc"
contains "a misspelled library function: the nearest" \
  "spwan.lua:1: pitwall has no function spwan; did you mean pitwall.spawn?" "$err"
printf 'local cars = pitwall.cars()\ncars[9]:setSpeed(500)\n' > "$TMP/list.lua"
err=$(cd "$TMP" && "$PITWALL" run list.lua --fast 2>&1 >/dev/null); rc=$?
check "a car past the end of a list: exit status" 1 "$rc"
contains "a car past the end of a list: what it holds" \
  "list.lua:2: this list of cars has no [9]; it holds $cars" "$err"
# at the REPL, its `cars` by number and by name
out=$(printf 'cars[9]:setSpeed(500)\ncars.groundshok:setSpeed(500)\npitwall.spwan(print)\n' |
  (cd "$TMP" && timeout 30 "$PITWALL" repl 2>&1))
contains "REPL: cars[9]" "stdin:1: cars[9] is nil: there is no car 9; the cars are $cars" "$out"
contains "REPL: cars.groundshok" \
  "stdin:1: cars.groundshok is nil: there is no car groundshok; did you mean cars.groundshock? The cars are $cars" "$out"
contains "REPL: pitwall.spwan" "stdin:1: pitwall has no function spwan; did you mean pitwall.spawn?" "$out"

finish
