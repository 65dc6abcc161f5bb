# Every example runs to its end on the simulator without a script error (docs stay true).
source "$(dirname "$0")/lib.sh"
for script in "$SRC"/examples/*.lua; do
  name=$(basename "$script")
  err=$(LAPS=2 $PITWALL run "$script" --fast --cars 2 --duration 120 2>&1 >"$TMP/out"); rc=$?
  check "$name exit status" 0 "$rc"
  case "$err" in *"error "*) fail "$name reported an error: $err" ;; *) echo "ok: $name ran cleanly" ;; esac
  [ -s "$TMP/out" ] && echo "ok: $name printed something" || fail "$name printed nothing"
done
out=$(LAPS=2 $PITWALL run "$SRC/examples/lap_times.lua" --fast --cars 4 2>/dev/null)
check "lap_times prints 2 laps for each of 4 cars" 8 "$(echo "$out" | grep -c ' lap [0-9]')"
finish
