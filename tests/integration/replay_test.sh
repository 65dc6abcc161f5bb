# pitwall replay and pitwall track show (docs/view.md "Replays", docs/cli.md): a --fast race's
# record replayed through the codec and the car model gives the laps the race library counted; a
# corrupt or hostile record replays what is whole and names the bad lines; a script sees the
# recorded events and drives nothing; the race view plays, pauses and seeks a record; a layout is
# drawn as well-formed SVG.
source "$(dirname "$0")/lib.sh"
PY=/usr/bin/python3  # Debian's, with python3-websocket

# A small grand prix, recorded.
LAPS=3 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --cars 4 --record "$TMP/r.jsonl" \
  --results "$TMP/res.json" >/dev/null 2>"$TMP/run.err"
check "the recorded race ends well" 0 "$?"

# The summary, as JSON lines, against the race's results. Before the race the scan lap and the
# drive to the grid also cross the line, so the replay counts more laps than the race did: the
# race's laps are the last N of the replay's (N the race's laps), so its last lap is the replay's
# last, and its best the best of those N, within 1 ms (times recomputed from the frames' own
# microsecond stamps; the race timed the same transitions).
$PITWALL replay "$TMP/r.jsonl" --summary --json >"$TMP/sum.json" 2>"$TMP/sum.err"
check "replay --json: exit status" 0 "$?"
agree=$($PY - "$TMP/res.json" "$TMP/sum.json" <<'PY'
import json, sys
race = json.load(open(sys.argv[1]))
rows = {r["car"]: r for r in map(json.loads, open(sys.argv[2]))}
assert sorted(rows) == [1, 2, 3, 4], sorted(rows)
for r in race:
    s = rows[r["number"]]
    n = r["laps"]
    assert n == 3 and s["laps"] >= n and len(s["lapTimes"]) == s["laps"], (r, s)
    mine = s["lapTimes"][-n:]
    assert abs(mine[-1] - r["lastLap"]) < 1e-3, (r, s)
    assert abs(s["lastLap"] - r["lastLap"]) < 1e-3, (r, s)
    assert abs(min(mine) - r["bestLap"]) < 1e-3, (r, s)
    assert s["framesIn"] > 50 and s["framesOut"] > 0 and s["malformed"] == 0, s
print("agree", len(race))
PY
)
check "the replay's laps agree with the race's" "agree 4" "$agree"

table=$($PITWALL replay "$TMP/r.jsonl" 2>/dev/null)
check "without options: the table, a row per car" 5 "$(echo "$table" | wc -l | tr -d ' ')"
contains "the table's header" "CAR  NAME              LAPS      BEST      LAST       IN      OUT MALFORMED DROPS" "$table"
contains "the cars by the names the record keeps" "1    groundshock" "$table"
check "no \"not sent\" line for the greeting every car gets when it connects" 0 \
  "$($PITWALL replay "$TMP/r.jsonl" 2>&1 | grep -c 'not sent')"

# A corrupt copy: a garbage line in the middle (line 101), the last line cut in half.
lines=$(wc -l <"$TMP/r.jsonl")
{ head -n 100 "$TMP/r.jsonl"; printf 'garbage \xff\xfe here\n'; sed -n "101,$((lines - 1))p" "$TMP/r.jsonl"
  tail -n 1 "$TMP/r.jsonl" | head -c 60; } >"$TMP/c.jsonl"
last=$((lines + 1))
$PITWALL replay "$TMP/c.jsonl" --json >"$TMP/c.json" 2>"$TMP/c.err"
check "a corrupt record replays: exit status" 0 "$?"
contains "the garbage line is named" "c.jsonl:101: not JSON" "$(cat "$TMP/c.err")"
contains "the cut last line is named" "c.jsonl:$last: not JSON" "$(cat "$TMP/c.err")"
check "a corrupt record: a row per car" 4 "$(wc -l <"$TMP/c.json" | tr -d ' ')"

# Hostile lines: none may crash the reader (a crash is a status above 128).
$PY - "$TMP/h.jsonl" <<'PY'
import sys
good = b'{"t":1.0,"car":1,"dir":"rx","hex":"01 17"}'
lines = [
    b'{"t":1e400,"car":1,"dir":"rx","hex":"01 17"}',
    b'{"t":1.0,"car":18446744073709551615,"dir":"rx","hex":"01 17"}',
    b'{"t":1.0,"car":99999999999999999999999,"dir":"rx","hex":"01 17"}',
    b'{"t":1.0,"car":1,"dir":"rx","hex":"\xff\xfe"}',
    b'\xc3\x28\xa0\xa1',
    b'[' * 10000 + b']' * 10000,
    b'{"a":' * 10000 + b'1' + b'}' * 10000,
    b'{"t":1.0,"car":1,"dir":"rx","hex":"' + b'ab' * 500000 + b'"}',
    b'\x00' * 100,
]
open(sys.argv[1], "wb").write(b"\n".join(lines) + b"\n")
open(sys.argv[1] + ".good", "wb").write(b"\n".join(lines + [good, b'{"t":1.5,"car":1,"dir":"rx","hex":"ff ff"}']))
PY
$PITWALL replay "$TMP/h.jsonl" >/dev/null 2>"$TMP/h.err"
check "a record of hostile lines only: exit status 1" 1 "$?"
contains "it says there is no frame" "has no line that is a frame (9 bad lines)" "$(cat "$TMP/h.err")"
check "each hostile line is named" 9 "$(grep -c '^.*h\.jsonl:[0-9]*: ' "$TMP/h.err")"
contains "the 1 MB line is skipped unread" "h.jsonl:8: a line of 1000037 bytes, longer than 65536" "$(cat "$TMP/h.err")"
contains "deep nesting is refused" "h.jsonl:6: nested deeper than 16 levels" "$(cat "$TMP/h.err")"
out=$($PITWALL replay "$TMP/h.jsonl.good" --json 2>"$TMP/hg.err")
check "hostile lines beside good ones: exit status 0" 0 "$?"
contains "the good frames replay, the malformed one counted" '"framesIn":1,"framesOut":0,"malformed":1,"drops":0' "$out"

$PITWALL replay "$TMP/none.jsonl" 2>"$TMP/e.err"
check "a missing file: exit status 2" 2 "$?"
contains "a missing file: says so" "cannot read $TMP/none.jsonl" "$(cat "$TMP/e.err")"
$PITWALL replay "$TMP" 2>/dev/null
check "a folder: exit status 2" 2 "$?"
: >"$TMP/empty.jsonl"
$PITWALL replay "$TMP/empty.jsonl" 2>"$TMP/e.err"
check "an empty file: exit status 1" 1 "$?"
contains "an empty file: says so" "empty.jsonl is empty" "$(cat "$TMP/e.err")"
$PITWALL replay "$TMP/r.jsonl" --speed 2 2>/dev/null
check "--speed without --view: a usage error" 2 "$?"

# A post-mortem: the script's handlers get the recorded events in virtual time, its commands are
# logged and not sent, and the run ends with the record.
cat >"$TMP/post.lua" <<'EOF'
local seen = 0
for _, car in ipairs(pitwall.cars()) do
  car.onPosition = function(c, ev)
    seen = seen + 1
    if seen == 1 then
      print(string.format("first position: %s piece %d at %.3f", c.name, ev.piece, pitwall.now()))
      c:setSpeed(300)
    end
  end
end
pitwall.every(5, function() print("positions " .. seen) end)
EOF
out=$($PITWALL replay "$TMP/r.jsonl" --script "$TMP/post.lua" 2>"$TMP/post.err")
check "--script: exit status" 0 "$?"
# (the car by the name its first line in the record carries)
first=$($PY -c '
import json, sys
lines = [l for l in map(json.loads, open(sys.argv[1])) if "dir" in l]  # frames (not the race, links)
names = {}
for l in lines:
    names.setdefault(l["car"], l.get("carName"))
l = next(l for l in lines if l["dir"] == "rx" and l["msg"]["name"] == "position-update")
print("first position: %s piece %d at %.3f" % (names[l["car"]], l["msg"]["piece_id"], l["t"]))' "$TMP/r.jsonl")
contains "--script: onPosition sees the first recorded position, at its time" "$first" "$out"
contains "--script: timers run in the record's time" "positions " "$out"
contains "--script: setSpeed is logged, not sent" "set-speed {\"accel_mm_s2\":1000,\"respect_limit\":false,\"speed_mm_s\":300} not sent: a replay" "$(cat "$TMP/post.err")"
contains "--script: the run ends with the record" "the record is over" "$(cat "$TMP/post.err")"

# track show: the summary, a well-formed SVG, and a bad layout's sentence with status 2.
out=$($PITWALL track show oval --svg "$TMP/oval.svg" 2>/dev/null)
check "track show: exit status" 0 "$?"
contains "track show: the summary" "oval: 9 pieces" "$out"
svg=$($PY - "$TMP/oval.svg" <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
print(root.tag, len(list(root.iter())) > 10)
PY
)
check "track show: a well-formed SVG" "{http://www.w3.org/2000/svg}svg True" "$svg"
check "track show --svg -: the SVG alone on stdout" "<svg" "$($PITWALL track show kidney --svg - 2>/dev/null | head -c 4)"
printf 'start S L L S\n' >"$TMP/bad.layout"
$PITWALL track show "$TMP/bad.layout" 2>"$TMP/t.err"
check "track show, a bad layout: exit status 2" 2 "$?"
contains "track show, a bad layout: the parser's sentence" "the layout does not close" "$(cat "$TMP/t.err")"

# A record whose layout does not parse: --view says so, with the parser's sentence, and how to go
# on (--track); nothing is served.
{ printf '{"t":0,"car":1,"dir":"rx","hex":"01 17","layout":"start S L"}\n'; } >"$TMP/badlayout.jsonl"
$PITWALL replay "$TMP/badlayout.jsonl" --view 127.0.0.1:0 >/dev/null 2>"$TMP/badlayout.err"
check "a record's broken layout: exit status 2" 2 "$?"
contains "a record's broken layout: said" "the record's layout: " "$(cat "$TMP/badlayout.err")"
contains "a record's broken layout: what to do" "--track" "$(cat "$TMP/badlayout.err")"

# The race view: the record played at 5× speed; /api/state has the replay object and the cars
# placed on the drawn track; a pause and seeks over the WebSocket move the position (and the laps
# with it, backwards as well as forwards); Ctrl-C ends it.
$PITWALL replay "$TMP/r.jsonl" --view 127.0.0.1:0 --speed 5 2>"$TMP/view.err" &
viewer=$!
if wait_for "$TMP/view.err" "^view: http://127.0.0.1:[0-9]+/"; then
  url=$(grep -oE -m1 'http://127.0.0.1:[0-9]+/' "$TMP/view.err")
  result=$(timeout 60 $PY - "$url" "$TMP/r.jsonl" <<'PY'
import json, sys, time, urllib.request
import websocket  # Debian's python3-websocket
base = sys.argv[1]
deadline = time.time() + 30
while True:  # the state of another process: polled, bounded
    s = json.load(urllib.request.urlopen(base + "api/state", timeout=5))
    r = s["replay"]
    assert r and r["file"] == "r.jsonl" and r["duration"] > 30 and r["speed"] == 5, r
    if any(c["x"] is not None and c["y"] is not None for c in s["cars"]):
        break
    assert time.time() < deadline, ("no car placed", s["cars"])
    time.sleep(0.05)
# the record keeps its layout and the cars' names: the view draws that track, with those names
assert s["source"] == "replay" and s["track"]["name"] == "recorded" and len(s["cars"]) == 4, s
assert len(s["track"]["pieces"]) == 9, s["track"]
assert [c["name"] for c in s["cars"]] == ["groundshock", "skull", "thermo", "nuke"], s["cars"]
ws = websocket.create_connection(base.replace("http://", "ws://") + "ws", timeout=10)
assert json.loads(ws.recv())["type"] == "state"
def until(pred, what):
    end = time.time() + 20
    while time.time() < end:
        m = json.loads(ws.recv())
        if m.get("type") == "update" and pred(m):
            return m
    raise SystemExit("timeout: " + what)
def laps(m):
    return sum(c["lap"] for c in m["cars"])
ws.send(json.dumps({"type": "control", "pause": True}))
until(lambda m: m["replay"]["paused"], "pause")
ws.send(json.dumps({"type": "control", "seek": 30}))
at30 = until(lambda m: abs(m["replay"]["position"] - 30) < 1e-3, "seek to 30")
ws.send(json.dumps({"type": "control", "seek": 2}))
at2 = until(lambda m: abs(m["replay"]["position"] - 2) < 1e-3, "seek back to 2")
assert laps(at30) > laps(at2), (laps(at30), laps(at2))
assert at2["cars"][0]["framesIn"] < at30["cars"][0]["framesIn"], "frames counted twice"
ws.send(json.dumps({"type": "control", "seek": 30}))
again = until(lambda m: abs(m["replay"]["position"] - 30) < 1e-3, "seek to 30 again")
assert [c["lapTimes"] for c in again["cars"]] == [c["lapTimes"] for c in at30["cars"]], "not the same"
assert [c["framesIn"] for c in again["cars"]] == [c["framesIn"] for c in at30["cars"]]
# The race as it was (the record keeps the race library's lines): at the first line of each
# phase, that phase, the title and the drivers; at the end the race's own laps, 3 per car, not
# the scan and grid laps the cars' trackers count too.
races = [j for j in map(json.loads, open(sys.argv[2])) if "race" in j and "car" not in j]
first = {}
for line in races:
    r = line["race"]
    if r and r.get("phase") not in first:
        first[r["phase"]] = line["t"]
assert list(first) == ["scan", "grid", "lights", "racing", "ending", "done"], list(first)
ws.send(json.dumps({"type": "control", "pause": True}))
for phase, t in first.items():
    ws.send(json.dumps({"type": "control", "seek": t + 0.0005}))
    m = until(lambda m: abs(m["replay"]["position"] - (t + 0.0005)) < 1e-3, "seek to " + phase)
    r = m["race"]
    assert r and r["phase"] == phase and r["title"] == "Grand prix, 3 laps", (phase, r and r.get("phase"))
    if phase in ("racing", "ending", "done"):
        assert sorted(row["driver"] for row in r["rows"]) == ["cruiser", "follower", "lanekeeper", "overtaker"], r["rows"]
        gaps = [row["gap"] for row in r["rows"] if row.get("gap") is not None]
        assert gaps == sorted(gaps), gaps
assert all(len(times) == 3 for times in r["lapTimes"].values()), r["lapTimes"]
assert any(c["lap"] > 3 for c in m["cars"]), "the trackers count the scan and grid laps too"
print("ok", laps(at2), laps(at30), " ".join(first))
PY
)
  contains "the view plays, pauses and seeks the record" "ok " "$result"
  contains "the replay's view shows the race's phases" "scan grid lights racing ending done" "$result"
  # the page itself at the end, paused there: the podium over the track, its title, the winner
  # (and a test artefact: ./view_test_artifacts/replay-done.png)
  chrome=(timeout 60 "${CHROMIUM:-/usr/bin/chromium}" --headless=new --no-sandbox --disable-gpu
    --window-size=1600,1000 --virtual-time-budget=5000)
  dom=$("${chrome[@]}" --dump-dom "$url" 2>/dev/null)
  contains "the replay's page: the race's title" '<div id="race-title" class="race-title">Grand prix, 3 laps</div>' "$dom"
  contains "the replay's page: the podium" '<li data-position="1"><span class="place">1</span>' "$dom"
  mkdir -p view_test_artifacts
  "${chrome[@]}" --screenshot="$PWD/view_test_artifacts/replay-done.png" "$url" >/dev/null 2>&1
  [ -s view_test_artifacts/replay-done.png ] && echo "ok: screenshot of the replay" ||
    fail "no screenshot of the replay"
else
  fail "replay --view printed no URL: $(cat "$TMP/view.err")"
fi
kill -INT "$viewer"
wait "$viewer"
check "replay --view ends on Ctrl-C" 130 "$?"
finish
