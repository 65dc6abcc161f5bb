# The live leaderboard on a terminal (a pseudo-terminal from script(1)): it redraws in place, a
# log line that comes between two drawings is not drawn over (the next drawing starts below it),
# and the final table is printed once.
source "$(dirname "$0")/lib.sh"

cat >"$TMP/board.lua" <<'LUA'
local race = require "pitwall.race"
pitwall.after(8, function() pitwall.log("warn", "a log line between two drawings") end)
race.laps { laps = 2, redraw = 0.5,
  drivers = function(car, i) return race.Steady.new { speed = 700 + 100 * i } end }
pitwall.stop()
LUA
script -qfec "$PITWALL run $TMP/board.lua --fast --cars 2" "$TMP/typescript" >/dev/null 2>&1
check "exit status" 0 "$?"
python3 - "$TMP/typescript" <<'PY' || fail "the drawing on the terminal"
import re, sys
data = open(sys.argv[1], "rb").read().decode("utf-8", "replace")
up = re.compile(r"\x1b\[\d+A")
assert len(up.findall(data)) > 5, "the board redraws in place"
i = data.find("a log line between two drawings")
assert i >= 0, "the log line reached the terminal"
after = data[data.index("\n", i) + 1:]
assert not up.match(after), "the next drawing moves up over the log line: " + repr(after[:40])
assert after.startswith("\x1b[2KRace"), "it starts anew below it: " + repr(after[:40])
assert data.count("Race   results") == 1, "the final table once, got %d" % data.count("Race   results")
print("ok: redrawn in place, not over the log line; the final table once")
PY
finish
