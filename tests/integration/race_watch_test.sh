# The grand prix edited while it races, as a user does it: `pitwall run grand_prix.lua --watch`,
# in real time on the simulator and over --ble against the fake BlueZ, 2 laps. Mid-race car 1's
# cruiser is saved at 600 mm/s instead of 950, then a broken version is saved, then one more good
# one. The race goes on through all of it and finishes as one race: one scan lap, one green light,
# no stop to any car before the first finish, car 1 commanded at most 600 mm/s after the save,
# and the results of one race. Also a broken save of a module, and of pitwall's own library
# (PITWALL_SCRIPTS), keeps the running version.
source "$(dirname "$0")/ble_lib.sh"

mkdir -p "$TMP/proj"
GP="$TMP/proj/grand_prix.lua"

# save TEXT-FILTER…: writes the grand prix through sed expressions, as an editor's atomic save
save() {
  sed "$@" "$SRC/examples/grand_prix.lua" >"$GP.swp" && mv "$GP.swp" "$GP"
}
SLOW='s/{ "cruiser", { speed = 950 } }/{ "cruiser", { speed = 600 } }/'

# wait_count FILE PATTERN N: until FILE has N lines matching PATTERN (at most 20 s)
wait_count() {
  local deadline=$((SECONDS + 20))
  until [ "$(grep -cE -- "$2" "$1")" -ge "$3" ]; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.05
  done
}

# stamp FILE PATTERN: the engine time of the first log line matching PATTERN
stamp() { grep -m1 -E -- "$2" "$1" | sed -n 's/^\[ *\([0-9.]*\)\].*/\1/p'; }

# gp_watch NAME ARGS…: one grand prix run with --watch and the saves; then the checks.
gp_watch() {
  local name=$1 out err pid rc
  shift
  out="$TMP/$name.out" err="$TMP/$name.err"
  cp "$SRC/examples/grand_prix.lua" "$GP"
  LAPS=2 $PITWALL --log-level debug run "$GP" --watch --results "$TMP/$name.csv" \
    --record "$TMP/$name.rec" "$@" >"$out" 2>"$err" &
  pid=$!
  wait_for "$err" "race: green" 120 || fail "$name: the race never went green: $(tail -5 "$err")"
  save -e "$SLOW"
  wait_for "$err" "version 2 took over" || fail "$name: version 2 did not take over: $(tail -5 "$err")"
  printf 'local race = require "pitwall.race"\nrace.laps {\n' >"$GP"
  wait_for "$err" "not started" || fail "$name: the broken version was not refused"
  save -e "$SLOW" -e 's/Grand prix, %d laps/GP, %d laps/'
  wait_for "$err" "version 3 took over" || fail "$name: version 3 did not take over: $(tail -5 "$err")"
  wait $pid
  rc=$?
  check "$name: exit status" 0 "$rc"
  contains "$name: the winner, after 2 laps" ", 2 laps in " "$(grep '^Winner: ' "$out")"
  contains "$name: the last version's title" "GP, 2 laps   results" "$(cat "$out")"
  check "$name: one scan lap" 1 "$(grep -c 'race: scan lap with' "$err")"
  check "$name: one green light" 1 "$(grep -c 'race: green' "$err")"
  check "$name: the race taken up twice" 2 "$(grep -c 'taken up by the new version (racing)' "$err")"
  contains "$name: the refusal names file and line" "grand_prix.lua:3:" "$(grep 'not started' "$err")"
  check "$name: no other error" "" "$(grep -E '\] error ' "$err" | grep -v 'not started')"
  check "$name: a row per car" 5 "$(wc -l <"$TMP/$name.csv" | tr -d ' ')"
  check "$name: every car finished" 4 "$(grep -c ',true,false,[a-z]*,[^,]*,finished,$' "$TMP/$name.csv")"
  check "$name: the winner's 2 laps" 2 "$(sed -n 2p "$TMP/$name.csv" | cut -d, -f4)"
  python3 - "$TMP/$name.rec" "$(stamp "$err" 'race: green')" "$(stamp "$err" 'version 2 took over')" \
    "$(stamp "$err" 'race: .* finished \(')" <<'PY' || fail "$name: commands in the record"
import json, sys
rec, green, swap, first_finish = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
after, bad = [], []
for line in open(rec):
    f = json.loads(line)
    m = f.get("msg", {})
    if f.get("dir") != "tx" or m.get("name") != "set-speed":
        continue
    if green < f["t"] < first_finish and m["speed_mm_s"] == 0:
        bad.append(f"stop to car {f['car']} at {f['t']}")
    if f["car"] == 1 and swap < f["t"] < first_finish:
        after.append(m["speed_mm_s"])
print("car 1 after the save:", sorted(set(after)))
assert not bad, bad
assert after and max(after) <= 600, f"car 1 commanded {max(after) if after else None} mm/s"
print("ok: no stop before the first finish; car 1 at most 600 mm/s after the save")
PY
}

gp_watch sim --cars 4

start_bus
start_fake --adapters 1 --cars 4
gp_watch ble --ble --scan-timeout 1
stop_fake
check "ble: every car left stopped" 4 "$(grep -c 'connected=false target=0 ' "$TMP/fake.out")"

# A module and pitwall's own library, saved broken: refused, the running version carries on.
cp -r "$SRC/scripts" "$TMP/lib"
cat >"$TMP/proj/speeds.lua" <<'LUA'
return { fast = 700 }
LUA
cat >"$TMP/proj/mod.lua" <<'LUA'
local speeds = require "speeds"
local board = require "pitwall.board"
pitwall.every(0.2, function() print("tick fast=" .. speeds.fast .. " " .. board.time(61)) end)
LUA
PITWALL_SCRIPTS="$TMP/lib" $PITWALL run "$TMP/proj/mod.lua" --watch --cars 1 >"$TMP/mod.out" \
  2>"$TMP/mod.err" &
pid=$!
wait_for "$TMP/mod.out" "^tick fast=700 1:01.000" || fail "module: first version: $(cat "$TMP/mod.err")"
printf 'return { fast = \n' >"$TMP/proj/speeds.lua"
wait_for "$TMP/mod.err" "not started" && echo "ok: module: the broken save is refused" ||
  fail "module: no refusal: $(cat "$TMP/mod.err")"
contains "module: the refusal names the module's line" "speeds.lua:2:" "$(cat "$TMP/mod.err")"
wait_count "$TMP/mod.out" "^tick" $(($(grep -c "^tick" "$TMP/mod.out") + 2)) &&
  echo "ok: module: the running version carries on" || fail "module: it stopped ticking"
printf 'return { fast = 650 }\n' >"$TMP/proj/speeds.lua"
wait_for "$TMP/mod.out" "^tick fast=650" && echo "ok: module: the fix reloads" || fail "module fix"
sed 's/^function Board.time(seconds)$/function Board.time(seconds)\n  if seconds then return "t" .. seconds end/' \
  "$SRC/scripts/pitwall/board.lua" >"$TMP/lib/pitwall/board.lua.swp"
mv "$TMP/lib/pitwall/board.lua.swp" "$TMP/lib/pitwall/board.lua"
wait_for "$TMP/mod.out" "^tick fast=650 t61" && echo "ok: library: a save of pitwall.board reloads" ||
  fail "library save: $(tail -3 "$TMP/mod.err")"
printf 'local Board = {}\nfunction Board.time(\n' >"$TMP/lib/pitwall/board.lua"
wait_for "$TMP/mod.err" "board.lua:3:" && echo "ok: library: a broken save is refused" ||
  fail "library: no refusal: $(tail -3 "$TMP/mod.err")"
wait_count "$TMP/mod.out" "^tick fast=650 t61" $(($(grep -c "^tick fast=650 t61" "$TMP/mod.out") + 2)) &&
  echo "ok: library: the running version carries on" || fail "library: it stopped ticking"
kill -INT $pid
wait $pid
check "module: Ctrl-C exit status" 130 "$?"

finish
