# A handler that fails on every event (issue 14): its traceback is printed once, then one line a
# simulated second counts the failures that followed; the counts add up and the run carries on.
source "$(dirname "$0")/lib.sh"

cat > "$TMP/flood.lua" <<'LUA'
for _, car in ipairs(pitwall.cars()) do car:setSpeed(600) end
pitwall.cars()[2].onPosition = function(car, ev)
  io.write("call\n")  -- one line per failure, counted below
  error("skull says no at piece " .. ev.piece)
end
LUA
# --handler-errors 0: the car drives on, as this is about the log (the stop for a handler that keeps
# failing: handler_errors_test.sh)
# --sensor ideal: a position update, and so a failure, every code (a real car's curves at
# 600 mm/s send few, and a pause of a second starts a new flood with a traceback of its own)
out=$($PITWALL run "$TMP/flood.lua" --fast --duration 20 --cars 2 --handler-errors 0 --sensor ideal \
  2>"$TMP/err"); rc=$?
check "exit status" 0 "$rc"
calls=$(printf '%s\n' "$out" | grep -c '^call$')
[ "$calls" -ge 50 ] && echo "ok: the handler failed on every event ($calls)" ||
  fail "too few events to call it a flood: $calls"
check "one traceback" 1 "$(grep -c 'stack traceback:' "$TMP/err")"
check "one full error" 1 "$(grep -c 'error in onPosition handler of car 2 (skull): .*flood.lua:4: skull says no' "$TMP/err")"
counted=$(sed -n 's/.*onPosition handler of car 2 (skull) failed \([0-9]*\) more times\{0,1\}: .*/\1/p' "$TMP/err")
lines=$(printf '%s\n' "$counted" | grep -c .)
sum=$(printf '%s\n' "$counted" | awk '{s += $1} END {print s + 0}')
check "the counts add up to the failures after the first" "$((calls - 1))" "$sum"
# A line a simulated second, and one more for the count pending when the run ended.
[ "$lines" -ge 18 ] && [ "$lines" -le 21 ] && echo "ok: $lines count lines in 20 s" ||
  fail "count lines: $lines"
contains "a count line quotes the latest error" "more times: $TMP/flood.lua:4: skull says no at piece" "$(cat "$TMP/err")"

finish
