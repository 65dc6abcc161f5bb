# Shared by the ghost tests (ghost_test, ghost_run_test, ble_race_test): sourced after lib.sh.

# ghost_laps RECORD TIME MIN TOLERANCE [REPLAY OPTIONS…]: the laps of the car named "ghost" in
# RECORD, counted by `pitwall replay` from its own frames: at least MIN of them, each TIME s
# within TOLERANCE s. Says ok or fails.
ghost_laps() {
  local record=$1 want=$2 min=$3 tolerance=$4
  shift 4
  if $PITWALL replay "$record" --json "$@" 2>/dev/null | python3 -c '
import json, sys
want, least, tolerance = float(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
rows = [json.loads(l) for l in sys.stdin]
times = next(r for r in rows if r["name"] == "ghost")["lapTimes"]
print("ghost laps:", times, "want:", want)
assert len(times) >= least, times
assert all(abs(t - want) <= tolerance for t in times), times
' "$want" "$min" "$tolerance"; then
    echo "ok: $record: every ghost lap in $want s within $tolerance s"
  else
    fail "$record: the ghost's lap times"
  fi
}
