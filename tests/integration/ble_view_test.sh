# The race view with real cars (docs/view.md "track"): `pitwall run examples/grand_prix.lua --ble
# --view` against the fake BlueZ, whose cars are simulated behind D-Bus on the kidney layout. No
# layout is known at the start; the race library's scan lap learns the map and the view draws it
# ("source": "scan"): the same pieces, in the same order, turning the same ways as the layout the
# cars really drive, and the cars are placed on it, on the road.
source "$(dirname "$0")/ble_lib.sh"
start_bus
start_fake --adapters 1 --cars 2 --track kidney

LAPS=20 "$PITWALL" run "$SRC/examples/grand_prix.lua" --ble --scan-timeout 1 --view 127.0.0.1:0 \
  >"$TMP/run.out" 2>"$TMP/run.err" &
RUN_PID=$!
wait_for "$TMP/run.err" '^view: http://' 20 || { fail "no view URL"; cat "$TMP/run.err"; finish; }
url=$(grep -oE '^view: http://[^ ]+' "$TMP/run.err" | head -1 | sed 's/^view: //')
expected=$("$PITWALL" track show kidney 2>/dev/null | sed -n 's/^ *[0-9]* *id \([0-9]*\) *\([a-z-]*\) *\([a-z]*\) *$/\1 \2 \3/p' |
  tr -s ' ' | sed 's/ $//' | paste -sd, -)
result=$(timeout 90 python3 - "$url" <<'PY'
import json, math, sys, time, urllib.request
url = sys.argv[1] + "api/state"
deadline = time.time() + 80
first = json.load(urllib.request.urlopen(url, timeout=5))
before = "none" if first["track"] is None else first["track"]["source"]
while time.time() < deadline:
    s = json.load(urllib.request.urlopen(url, timeout=5))
    t = s["track"]
    if t and t["source"] == "scan":
        placed = [c for c in s["cars"] if c["x"] is not None]
        if len(placed) == 2:
            b = t["bounds"]
            inside = all(b["minX"] <= c["x"] <= b["maxX"] and b["minY"] <= c["y"] <= b["maxY"]
                         for c in placed)
            turn = {1: "left", -1: "right", 0: ""}
            pieces = ",".join(f'{p["id"]} {p["type"]} {turn[p["turn"]]}'.strip() for p in t["pieces"])
            print(s["source"], before, "inside" if inside else "outside", pieces)
            sys.exit(0)
    time.sleep(0.2)
print("timeout", before)
PY
)
contains "the view's cars are real ones (ble)" "ble " "$result"
contains "no track before the scan" "ble none " "$result"
contains "the cars are placed on the scanned map" " inside " "$result"
check "the scanned map is the layout the cars drive (ids, types, turns)" "$expected" "${result##* inside }"
kill -INT "$RUN_PID"
wait "$RUN_PID"
status=$?
check "Ctrl-C: exit status" 130 "$status"
[ "$status" = 130 ] || { echo "the run's log:"; cat "$TMP/run.err"; }
stop_fake
finish
