# pitwall league (docs/league.md): submitted drivers — good ones and adversaries — qualify and race
# heats in the simulator. The draw covers every pair; the league is the same twice for a seed and
# with -j 2 as with -j 1; every adversary is DNF with its reason in each of its heats and scores
# nothing while the good ones finish; the results come as JSON and CSV; the HTML report loads in
# Chromium with a lap-time chart per heat (its screenshot is kept in test-results/). Bad
# invocations are sentences.
source "$(dirname "$0")/lib.sh"
D="$SRC/tests/integration/drivers"
SHOTS="$(cd "$(dirname "$PITWALL")" && pwd)/test-results"
mkdir -p "$SHOTS" "$TMP/class"

good_class "$TMP/class"
cp "$D/loop.lua" "$TMP/class/eve.lua"
cp "$D/errors.lua" "$TMP/class/frank.lua"
cp "$D/other_car.lua" "$TMP/class/gina.lua"
cp "$D/broken_save.lua" "$TMP/class/hank.lua"  # does not compile: enters, and is out
cp "$D/require_other.lua" "$TMP/class/ivan.lua"
cp "$D/bad_bytes.lua" "$TMP/class/jack.lua"  # fails with bytes that are not UTF-8, and markup

league() {
  $PITWALL league "$TMP/class" --laps 2 --qualifying-laps 1 --seed 3 "$@"
}

league --results "$TMP/a.json" --report "$TMP/report.html" >"$TMP/a.out" 2>"$TMP/a.err"
check "a league: exit status" 0 "$?"
contains "live progress: qualifying" "qualifying 10/10: jack" "$(cat "$TMP/a.err")"
contains "live progress: the heats" "heat 1/" "$(cat "$TMP/a.err")"
contains "the file that does not compile is named" "hank enters, and is out" "$(cat "$TMP/a.err")"
contains "the standings printed" "POS  DRIVER" "$(cat "$TMP/a.out")"

python3 - "$TMP/a.json" <<'PY' >"$TMP/checks.txt"
import itertools, json, sys
league = json.load(open(sys.argv[1]))
names = [q["driver"] for q in league["qualifying"]]
print("drivers", len(names))
met = set()
for h in league["heats"]:
    met.update(itertools.combinations(sorted(h["grid"]), 2))
print("pairs", len(met), "of", len(names) * (len(names) - 1) // 2)
bad = {"eve": "still running after 50 ms", "frank": "this driver is broken",
       "gina": "is not this driver's car", "hank": "its file does not load",
       "ivan": "module 'good' not found", "jack": "bytes, <b>and markup</b>"}
for h in league["heats"]:
    for r in h["results"]:
        d = r["driver"]
        if d in bad:
            ok = r["status"] == "DNF" and bad[d] in r.get("reason", "") and r["points"] == 0
            print("adversary", d, "ok" if ok else "WRONG %s" % r)
        else:
            print("good", d, "ok" if r["status"] == "finished" else "WRONG %s" % r)
standings = league["standings"]
print("leader", standings[0]["driver"], standings[0]["points"])
print("nothing for adversaries", all(s["points"] == 0 for s in standings if s["driver"] in bad))
print("points add up", all(s["points"] == sum(r["points"] for h in league["heats"]
      for r in h["results"] if r["driver"] == s["driver"]) for s in standings))
PY
checks=$(cat "$TMP/checks.txt")
contains "ten drivers" "drivers 10" "$checks"
contains "the heats cover every pair" "pairs 45 of 45" "$checks"
case "$checks" in *WRONG*) fail "a driver's row: $(grep WRONG "$TMP/checks.txt")" ;; *) echo "ok: every row as expected" ;; esac
check "every adversary seen" 6 "$(grep '^adversary' "$TMP/checks.txt" | cut -d' ' -f2 | sort -u | wc -l)"
contains "the adversaries score nothing" "nothing for adversaries True" "$checks"
contains "the standings are the heats' points" "points add up True" "$checks"

league --results "$TMP/b.json" >/dev/null 2>&1
check "the same seed: the same league" "" "$(cmp "$TMP/a.json" "$TMP/b.json" 2>&1)"
league --results "$TMP/j2.json" -j 2 >/dev/null 2>&1
check "-j 2: the same league as -j 1" "" "$(cmp "$TMP/a.json" "$TMP/j2.json" 2>&1)"

# Beyond one machine: three shards, merged, are the one league
for k in 1 2 3; do
  league --shard "$k/3" --results "$TMP/shard$k.json" >/dev/null 2>"$TMP/shard$k.err"
  check "shard $k/3: exit status" 0 "$?"
done
contains "a shard says which heats it races" "shard 2/3 races" "$(cat "$TMP/shard2.err")"
$PITWALL league merge "$TMP/shard3.json" "$TMP/shard1.json" "$TMP/shard2.json" \
  --results "$TMP/merged.json" --report "$TMP/merged.html" >/dev/null 2>&1
check "merge: exit status" 0 "$?"
check "3 shards merged = one run" "" "$(cmp "$TMP/a.json" "$TMP/merged.json" 2>&1)"
[ -s "$TMP/merged.html" ] && echo "ok: merge: the report" || fail "merge: no report"
err=$($PITWALL league merge "$TMP/shard1.json" "$TMP/shard2.json" 2>&1); rc=$?
check "merge: a missing shard is refused (status 2)" 2 "$rc"
contains "merge: the missing heat is named" "is in none of the files: merge every shard's results" "$err"
err=$($PITWALL league merge "$TMP/shard1.json" "$TMP/shard1.json" "$TMP/shard2.json" "$TMP/shard3.json" 2>&1)
contains "merge: a shard twice" "shard 1/3 is given twice" "$err"
$PITWALL league "$TMP/class" --laps 1 --qualifying-laps 1 --seed 4 --shard 1/3 \
  --results "$TMP/other1.json" >/dev/null 2>&1
err=$($PITWALL league merge "$TMP/other1.json" "$TMP/shard2.json" "$TMP/shard3.json" 2>&1)
contains "merge: another league's shard" "another league than" "$err"
echo '{"not": "a league"}' >"$TMP/junk.json"
err=$($PITWALL league merge "$TMP/junk.json" 2>&1)
contains "merge: a file that is no league's results" "not the JSON results of a league" "$err"
err=$($PITWALL league "$TMP/class" --shard 3/2 2>&1)
contains "--shard K/N checked" "expected K/N, shard K of N" "$err"

league --results "$TMP/c.csv" >/dev/null 2>&1
check "CSV: the standings' header" "position,driver,points,heats,wins,finishes,bestLap,qualifying" \
  "$(head -1 "$TMP/c.csv")"
check "CSV: a row per driver" 10 "$(tail -n +2 "$TMP/c.csv" | wc -l)"

# The report in Chromium: its tables and a chart per heat, drawn
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
heats=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['heats']))" "$TMP/a.json")
dom=$(timeout 60 "$CHROMIUM" --headless=new --no-sandbox --disable-gpu --dump-dom \
  "file://$TMP/report.html" 2>/dev/null)
check "the report: a standings row per driver" 10 \
  "$(echo "$dom" | python3 -c "import re,sys; t=sys.stdin.read(); s=t[t.find('id=\"standings\"'):]; print(s[:s.find('</table>')].count('<tr>') - 1)")"
check "the report: a chart per heat" "$heats" "$(echo "$dom" | grep -o '<svg class="laps"' | wc -l)"
lines=$(echo "$dom" | grep -o '<polyline class="driver"' | wc -l)
[ "$lines" -ge "$heats" ] && echo "ok: the report: lap-time lines drawn ($lines)" ||
  fail "the report: $lines lines for $heats heats"
contains "the report: a driver's markup is text" "bytes, &lt;b&gt;and markup&lt;/b&gt;" "$dom"
case "$dom" in *"<b>and markup"*) fail "the report: a driver's markup became markup" ;; esac
timeout 60 "$CHROMIUM" --headless=new --no-sandbox --disable-gpu --hide-scrollbars \
  --window-size=1000,1800 --screenshot="$SHOTS/league-report.png" "file://$TMP/report.html" \
  >/dev/null 2>&1
[ -s "$SHOTS/league-report.png" ] && echo "ok: the report's screenshot: $SHOTS/league-report.png" ||
  fail "no screenshot of the report"

# Sentences for what cannot be a league
err=$($PITWALL league "$TMP/class/alice.lua" 2>&1); rc=$?
check "one driver: status 2" 2 "$rc"
contains "one driver: says why" "a league needs at least 2 drivers, got 1" "$err"
err=$($PITWALL league "$TMP/class" "$TMP/nowhere" 2>&1)
contains "a missing folder is named" "$TMP/nowhere: no such file or folder" "$err"
mkdir -p "$TMP/other" && cp "$D/good.lua" "$TMP/other/alice.lua"
err=$($PITWALL league "$TMP/class" "$TMP/other" 2>&1)
contains "two drivers of one name" "two drivers are named alice" "$err"
err=$($PITWALL league "$TMP/class" --report "$TMP/nowhere/r.html" 2>&1); rc=$?
check "a report into no folder: refused first (status 2)" 2 "$rc"
contains "a report into no folder: named" "--report $TMP/nowhere/r.html: no folder $TMP/nowhere" "$err"
case "$err" in *qualifying*) fail "the league ran before its report was refused" ;; esac
mkdir -p "$TMP/empty"
err=$($PITWALL league "$TMP/empty" 2>&1)
contains "a folder without drivers" "no driver files (*.lua) in this folder" "$err"

finish
