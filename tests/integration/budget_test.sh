# A runaway callback is interrupted after the budget (--budget) and reported; the run, its
# timers and the other cars carry on.
source "$(dirname "$0")/lib.sh"

cat > "$TMP/runaway.lua" <<'LUA'
local car = pitwall.cars()[1]
car:setSpeed(600)
local spun = false
car.onTransition = function()
  if not spun then
    spun = true
    while true do end  -- never returns
  end
end
local ticks = 0
pitwall.every(0.25, function() ticks = ticks + 1 end)
pitwall.after(2, function()
  print(string.format("ticks=%d moving=%s", ticks, tostring(car.speed > 0)))
  pitwall.stop()
end)
LUA
out=$($PITWALL run "$TMP/runaway.lua" --cars 1 2>"$TMP/err"); rc=$?
err=$(cat "$TMP/err")
check "exit status" 0 "$rc"
contains "reported as a runaway" "error in onTransition handler of car 1" "$err"
contains "after the default budget" "still running after 100 ms: interrupted" "$err"
contains "where it was" "runaway.lua:7" "$err"
ticks=$(echo "$out" | sed -n 's/ticks=\([0-9]*\).*/\1/p')
[ "${ticks:-0}" -ge 6 ] && echo "ok: timers kept running ($ticks)" || fail "timers: [$out]"
contains "the car still drives" "moving=true" "$out"

out=$($PITWALL run "$TMP/runaway.lua" --cars 1 --budget 0.4 2>&1)
contains "--budget sets it" "still running after 400 ms" "$out"

# A main chunk that waits by spinning is a task already: the hint is to pause, not to spawn.
printf 'local t = pitwall.now()\nwhile pitwall.now() < t + 1 do end\n' > "$TMP/spin.lua"
err=$($PITWALL run "$TMP/spin.lua" --cars 1 2>&1 >/dev/null)
contains "a spinning task is told to pause" "without a pause: interrupted (a task must give the loop its turn: call pitwall.sleep or pitwall.waitUntil" "$err"
case "$err" in *pitwall.spawn*) fail "the hint for a task names pitwall.spawn: [$err]" ;; *) echo "ok: no pitwall.spawn for a task" ;; esac

err=$($PITWALL run "$TMP/runaway.lua" --budget -1 2>&1 >/dev/null); rc=$?
check "a negative budget is refused" 2 "$rc"

finish
