# Falling behind real time is said (docs/simulator.md "Real time"): a script whose timer holds
# the loop 45 ms of every 50 ms makes a real-time run late; stderr says so once, with what to
# do, and the run goes on to its end. The simulated car moves on by the wall clock meanwhile.
source "$(dirname "$0")/lib.sh"

cat >"$TMP/hog.lua" <<'LUA'
local car = pitwall.cars()[1]
car:setSpeed(400)
pitwall.every(0.05, function()
  local t = os.clock()
  while os.clock() - t < 0.045 do end
end)
LUA
$PITWALL run "$TMP/hog.lua" --cars 1 --duration 5 >/dev/null 2>"$TMP/hog.err"
check "a hogging script: the run ends as asked" 0 $?
check "a hogging script: said once" 1 "$(grep -c 'the engine is falling behind real time' "$TMP/hog.err")"
contains "a hogging script: says what to do" "Give the callbacks less to do" "$(cat "$TMP/hog.err")"
contains "a hogging script: says how late" "ms late on average over the last 2 s" "$(cat "$TMP/hog.err")"

finish
