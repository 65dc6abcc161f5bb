# pitwall compare (docs/racing.md "Comparing laps"): two records of one car on the oval, the
# second slower in the first curve pair only (tests/integration/compare_drive.lua). The delta is
# flat before that curve, rises across it and stays level after it; the table shows the
# loss in that corner alone; the charts are written; what cannot be compared is a sentence.
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 2

cp "$SRC/tests/integration/compare_drive.lua" even.lua
sed 's/^local SLOW = false/local SLOW = true/' even.lua > slow.lua
check "the slow script differs in SLOW alone" 1 "$(diff even.lua slow.lua | grep -c '^> local SLOW = true')"
for sensor in real ideal; do
  $PITWALL run even.lua --fast --sensor $sensor --record even-$sensor.jsonl -q || fail "run even ($sensor)"
  $PITWALL run slow.lua --fast --sensor $sensor --record slow-$sensor.jsonl -q || fail "run slow ($sensor)"
done

# judge JSON SENSOR: the delta and the sections of B (slow) against A (even)
judge() {
  python3 - "$1" "$2" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
sensor = sys.argv[2]
bad = []
def expect(what, ok):
    print(("ok: " if ok else "FAIL: ") + sensor + ": " + what)
expect("two laps, B slower", len(c["laps"]) == 2 and c["laps"][1]["time"] > c["laps"][0]["time"] + 0.3)
expect("aligned by distance with every code, per piece as a real car reports",
       c["byDistance"] == (sensor == "ideal"))
curve = next(s for s in c["sections"] if s["name"] == "left 1")
lost = curve["times"][1] - curve["times"][0]
expect("the curve lost %.3f s (over 0.3)" % lost, lost > 0.3)
for s in c["sections"]:
    if s["name"] in ("left 1", "straight 2"):
        continue  # straight 2: B accelerates back to 800 mm/s at its start
    d = s["times"][1] - s["times"][0]
    expect("%s: the same in both laps (%+.3f s)" % (s["name"], d), abs(d) < 0.02)
dist, delta = c["distance"], c["delta"][1]
before = [x for d, x in zip(dist, delta) if d <= curve["from"]]
after = [x for d, x in zip(dist, delta) if d >= curve["to"]]
across = [x for d, x in zip(dist, delta) if curve["from"] <= d <= curve["to"]]
expect("flat before the curve (max |delta| %.4f s)" % max(map(abs, before)), max(map(abs, before)) < 0.01)
expect("rising across the curve", all(b >= a - 1e-6 for a, b in zip(across, across[1:])) and across[-1] - across[0] > 0.3)
expect("level after it (spread %.3f s)" % (max(after) - min(after)), max(after) - min(after) < 0.1)
expect("the lap's delta is the last", abs(delta[-1] - (c["laps"][1]["time"] - c["laps"][0]["time"])) < 1e-6)
PY
}
for sensor in real ideal; do
  $PITWALL compare even-$sensor.jsonl slow-$sensor.jsonl --json > cmp-$sensor.json 2> cmp-$sensor.err
  check "compare ($sensor): exit status" 0 $?
  check "compare ($sensor): nothing on stderr" "" "$(cat cmp-$sensor.err)"
  out=$(judge cmp-$sensor.json $sensor)
  echo "$out"
  if grep -q '^FAIL' <<< "$out"; then FAILURES=$((FAILURES + 1)); fi
done

# the table and the charts
$PITWALL compare even-real.jsonl:1:best slow-real.jsonl:groundshock:2 --out cmp.svg > table.txt
check "the table: exit status" 0 $?
contains "the table names both laps" "A  even-real.jsonl car 1 (groundshock) lap" "$(cat table.txt)"
contains "B is lap 2 of the car named" "B  slow-real.jsonl car 1 (groundshock) lap 2" "$(cat table.txt)"
contains "the table says how it aligned them" "per piece:" "$(cat table.txt)"
contains "the table has the curve" "left 1" "$(cat table.txt)"
python3 - cmp.svg <<'PY' && echo "ok: the SVG: three charts, two laps each" || fail "the SVG"
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
ns = "{http://www.w3.org/2000/svg}"
charts = [e for e in root.iter(ns + "svg") if e.get("class") in ("speed", "delta", "lane")]
assert [c.get("class") for c in charts] == ["speed", "delta", "lane"], charts
for c in charts:
    assert len([p for p in c.iter(ns + "polyline") if p.get("class") == "lap"]) >= 2, c.get("class")
PY
# the same charts as a PNG (the print module's librsvg): twice the SVG's size, drawn, not blank
$PITWALL compare even-real.jsonl:1:best slow-real.jsonl:groundshock:2 --out cmp.png > /dev/null
check "the PNG: exit status" 0 $?
python3 - cmp.png cmp.svg <<'PY' && echo "ok: the PNG: the SVG's charts at twice their size" || fail "the PNG"
import struct, sys, zlib, xml.etree.ElementTree as ET
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, idat, size = 8, b"", None
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR": size = struct.unpack(">II", body[:8])
    if kind == b"IDAT": idat += body
    pos += 12 + n
root = ET.parse(sys.argv[2]).getroot()
want = (round(2 * float(root.get("width"))), round(2 * float(root.get("height"))))
print("PNG", size, "SVG x2", want)
assert abs(size[0] - want[0]) <= 1 and abs(size[1] - want[1]) <= 1, (size, want)
# the pixels, unfiltered (8-bit RGB or RGBA, as cairo writes them)
ihdr = data[16:29]
channels = {2: 3, 6: 4}[ihdr[9]]
w, h = size
raw, stride, rows, prev = zlib.decompress(idat), w * channels, [], bytearray(w * channels)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - channels] if i >= channels else 0
        b, c = prev[i], prev[i - channels] if i >= channels else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(line)
    prev = line
px = [(r[i], r[i + 1], r[i + 2]) for r in rows[::4] for i in range(0, stride, channels * 4)]
ink = sum(1 for p in px if min(p) < 200)
orange = sum(1 for r, g, b in px if r > 150 and b < 100)
blue = sum(1 for r, g, b in px if b > 150 and r < 100)
print("pixels sampled:", len(px), "inked:", ink, "orange:", orange, "blue:", blue)
assert len(px) // 100 < ink < len(px) // 2, "blank, or all ink"
assert orange > 0 and blue > 0, "the two laps' lines are not drawn"
PY
$PITWALL compare even-real.jsonl slow-real.jsonl --out no/such/cmp.png > /dev/null 2> png.err
check "a PNG it cannot write: status 1" 1 $?
contains "a PNG it cannot write: the sentence" "pitwall compare: cannot write no/such/cmp.png" "$(cat png.err)"
$PITWALL compare even-ideal.jsonl slow-ideal.jsonl even-ideal.jsonl:1:1 --out cmp.html > three.txt
check "three laps: exit status" 0 $?
contains "three laps: C" "C  even-ideal.jsonl car 1 (groundshock) lap 1" "$(cat three.txt)"
check "the page: a table and three charts" "1 3" \
  "$(grep -o '<table class="sections"' cmp.html | wc -l) $(grep -oE '<svg class="(speed|delta|lane)"' cmp.html | wc -l)"

# a file name that is not UTF-8: the JSON still is
cp even-real.jsonl "$(printf 'caf\xe9.jsonl')"
$PITWALL compare "$(printf 'caf\xe9.jsonl')" slow-real.jsonl --json > latin.json 2> latin.err
check "a Latin-1 file name: exit status" 0 $?
python3 -c 'import json,sys; json.load(open(sys.argv[1], encoding="utf-8"))' latin.json &&
  echo "ok: a Latin-1 file name: the JSON is UTF-8" || fail "a Latin-1 file name: the JSON is not UTF-8"

# what cannot be compared: a sentence, and the status
$PITWALL compare even-real.jsonl slow-real.jsonl:1:99 > /dev/null 2> nolap.err
check "a lap the record lacks: status 1" 1 $?
contains "a lap the record lacks: the sentence" "slow-real.jsonl car 1 (groundshock) has no lap 99: its whole laps are 1, 2," "$(cat nolap.err)"
$PITWALL compare even-real.jsonl slow-real.jsonl:2 > /dev/null 2> standing.err
check "a car that drove no lap: status 1" 1 $?
contains "a car that drove no lap: the sentence" "car 2 (skull) drove no whole lap" "$(cat standing.err)"
$PITWALL compare even-real.jsonl slow-real.jsonl:nobody > /dev/null 2> nocar.err
check "no such car: status 1" 1 $?
contains "no such car: its cars listed" "has no car 'nobody': its cars are 1 (groundshock), 2 (skull)" "$(cat nocar.err)"
$PITWALL compare even-real.jsonl slow-real.jsonl:1:x > /dev/null 2> badlap.err
check "a lap that is no number: status 2" 2 $?
contains "a lap that is no number: the sentence" "the lap must be a number from 1 or \`best\`, not 'x'" "$(cat badlap.err)"
$PITWALL compare even-real.jsonl > /dev/null 2> one.err
check "one lap: status 2" 2 $?
contains "one lap: the sentence" "give two laps or more" "$(cat one.err)"
$PITWALL compare even-real.jsonl missing.jsonl > /dev/null 2> missing.err
check "a missing file: status 2" 2 $?
contains "a missing file: the sentence" "cannot read missing.jsonl: no such file" "$(cat missing.err)"
$PITWALL compare even-real.jsonl slow-real.jsonl --out cmp.pdf > /dev/null 2> ext.err
check "an --out it cannot write: status 2" 2 $?
contains "an --out it cannot write: the sentence" "written as .svg, .png or .html" "$(cat ext.err)"
# a record that keeps no layout (real cars'): the track must be given
sed '1s/"layout":"[^"]*",//' even-real.jsonl > nolayout.jsonl
$PITWALL compare nolayout.jsonl slow-real.jsonl > /dev/null 2> nolayout.err
check "no layout: status 2" 2 $?
contains "no layout: the sentence" "nolayout.jsonl keeps no track layout (a record of real cars)" "$(cat nolayout.err)"
$PITWALL compare nolayout.jsonl slow-real.jsonl --track oval > /dev/null
check "no layout, --track oval: compared" 0 $?
# laps on two tracks
$PITWALL run even.lua --fast --track kidney --record kidney.jsonl -q
$PITWALL compare even-real.jsonl kidney.jsonl > /dev/null 2> tracks.err
check "two tracks: status 2" 2 $?
contains "two tracks: the sentence" "kidney.jsonl was driven on another track than even-real.jsonl" "$(cat tracks.err)"

exit $((FAILURES > 0))
