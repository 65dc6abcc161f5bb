# How a --fast run ends (issue 14): a script that ends the run itself runs to its end, however
# long in simulated time; one that never does is stopped by the safety cap, which is stated at
# the start and, when it ends the run, says so and exits 124; --duration ends a run with 0.
source "$(dirname "$0")/lib.sh"

cat > "$TMP/long.lua" <<'LUA'
pitwall.cars()[1]:setSpeed(500)
pitwall.sleep(4000)  -- longer than the old silent cut at 3600 s
print(string.format("ended at %.0f", pitwall.now()))
pitwall.stop()
LUA
out=$($PITWALL run "$TMP/long.lua" --fast --cars 1 2>"$TMP/err"); rc=$?
check "a script that ends by itself after 4000 s: exit status" 0 "$rc"
check "it ran to its own end" "ended at 4000" "$out"
contains "the cap is stated at the start" "--fast: until the script ends, at most 86400 s (24 h) simulated (--fast-cap S)" "$(cat "$TMP/err")"

# The grand prix of 1000 laps (≈ 3760 simulated seconds, ≈ 6 s of wall time here) finishes
# with its winner and results; before issue 14 it was cut silently at 3600 s.
out=$(LAPS=1000 $PITWALL run "$SRC/examples/grand_prix.lua" --fast 2>"$TMP/err"); rc=$?
check "1000 laps: exit status" 0 "$rc"
grep -qE '^Winner: [a-z]+ \([a-z]+\), 1000 laps in [0-9]+ min [0-9.]+ s$' <<< "$out" &&
  echo "ok: 1000 laps: the winner" || fail "1000 laps: no winner in [$(printf '%s' "$out" | tail -3)]"
contains "1000 laps: the results" "Grand prix, 1000 laps   results" "$out"

cat > "$TMP/never.lua" <<'LUA'
pitwall.cars()[1]:setSpeed(500)
pitwall.every(10, function() end)  -- drives for ever, never calls pitwall.stop()
LUA
$PITWALL run "$TMP/never.lua" --fast --cars 1 --fast-cap 300 >/dev/null 2>"$TMP/err"; rc=$?
check "a script that never ends, stopped by the cap: exit status" 124 "$rc"
err=$(cat "$TMP/err")
contains "stated at the start" "at most 300 s simulated (--fast-cap S)" "$err"
contains "says what happened" "[  300.000] error pitwall: the script was still running after 300 s of simulated time, the --fast safety cap: stopping the cars" "$err"
contains "says what to do" "Give --duration S to a script that does not end the run itself (pitwall.stop()), or --fast-cap S to one that needs longer" "$err"
check "the cap is stated once and reported once" 2 "$(grep -c "300 s.*simulated" "$TMP/err")"

echo 'pitwall.every(60, function() end)' > "$TMP/idle.lua"
$PITWALL run "$TMP/idle.lua" --fast --cars 0 >/dev/null 2>"$TMP/err"; rc=$?
check "the default cap (24 h, no cars): exit status" 124 "$rc"
contains "the default cap" "still running after 86400 s (24 h) of simulated time" "$(cat "$TMP/err")"

$PITWALL run "$TMP/never.lua" --fast --cars 1 --duration 30 >/dev/null 2>"$TMP/err"; rc=$?
check "--duration ends the run: exit status" 0 "$rc"
contains "--duration says so" "the run's duration is over" "$(cat "$TMP/err")"
check "--duration: no cap" "" "$(grep 'safety cap' "$TMP/err")"

err=$($PITWALL run "$TMP/never.lua" --cars 1 --fast-cap 10 2>&1); rc=$?
check "--fast-cap without --fast: exit status" 2 "$rc"
contains "--fast-cap without --fast: says why" "--fast-cap requires --fast" "$err"

finish
