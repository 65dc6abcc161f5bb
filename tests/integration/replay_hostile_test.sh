# pitwall replay on hostile and huge records (issue 33, docs/cli.md "pitwall replay FILE",
# docs/safety.md "Hostile input"): bad lines are counted, not kept, and frames are read as they
# play, so memory does not grow with the file. Peak memory is the process's largest resident
# set, read by its parent (python's resource module); a generous timeout fails a hang.
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 2

# run_peak OUT ERR CMD…: runs CMD (stdout to OUT, stderr to ERR); prints "STATUS PEAK_MB".
run_peak() {
  local out=$1 err=$2
  shift 2
  python3 - "$out" "$err" "$@" <<'PY'
import resource, subprocess, sys
with open(sys.argv[1], "wb") as out, open(sys.argv[2], "wb") as err:
    try:
        rc = subprocess.run(sys.argv[3:], stdout=out, stderr=err, timeout=300).returncode
    except subprocess.TimeoutExpired:
        rc = 124
print(rc, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)
PY
}

# 1. 20 MB of bad lines (10⁶ of them) around one good frame: the first 20 named, the rest
# counted, in a few MB.
python3 - <<'PY'
with open("bad.jsonl", "w") as f:
    f.write('{"t":0.5,"car":1,"dir":"rx","hex":"01 17"}\n')
    for i in range(1_000_000):
        f.write("bad line %010d\n" % i)
PY
check "the bad record is 20 MB" 20000043 "$(stat -c %s bad.jsonl)"
res=$(run_peak bad.json bad.err $PITWALL replay bad.jsonl --json)
check "20 MB of bad lines: exit status" 0 "${res% *}"
peak=${res#* }
if ((peak < 100)); then echo "ok: 20 MB of bad lines: peak memory ${peak} MB, under 100 MB"; else
  fail "20 MB of bad lines: peak memory ${peak} MB, expected under 100 MB"; fi
check "20 MB of bad lines: the first 20 named" 20 "$(grep -c '^bad\.jsonl:[0-9]*: not JSON' bad.err)"
contains "the first bad line by its number" "bad.jsonl:2: not JSON" "$(cat bad.err)"
contains "the 20th bad line by its number" "bad.jsonl:21: not JSON" "$(cat bad.err)"
contains "the rest counted" "bad.jsonl: 999980 more bad lines" "$(cat bad.err)"
contains "the warning counts them all" "1000000 bad lines of bad.jsonl left out; replaying the 1 frames" "$(cat bad.err)"
contains "the good frame replays" '"framesIn":1,' "$(cat bad.json)"

# 2. A long valid record: 4 cars, 500 000 frames against 50 000. Memory does not grow with the
# length (before, each frame was held: ~200 bytes each, ~100 MB more for the long one).
make_record() {
  python3 - "$1" "$2" <<'PY'
import sys
n = int(sys.argv[2])
with open(sys.argv[1], "w") as f:
    for i in range(n):
        car = i % 4 + 1
        if i % 1000 == 999:
            f.write('{"t":%.6f,"car":%d,"dir":"tx","hex":"04 24 00 00"}\n' % (i * 0.001, car))
        else:
            f.write('{"t":%.6f,"car":%d,"dir":"rx","hex":"%s"}\n' % (i * 0.001, car, "01 17" if i % 2 else "03 1b 3c 0f"))
PY
}
make_record short.jsonl 50000
make_record long.jsonl 500000
res_short=$(run_peak short.json short.err $PITWALL replay short.jsonl --json)
res_long=$(run_peak long.json long.err $PITWALL replay long.jsonl --json)
check "a short record: exit status" 0 "${res_short% *}"
check "a long record: exit status" 0 "${res_long% *}"
short=${res_short#* } long=${res_long#* }
if ((long < short + 25)); then
  echo "ok: memory does not grow with the record: ${short} MB for 50 000 frames, ${long} MB for 500 000"
else
  fail "memory grows with the record: ${short} MB for 50 000 frames, ${long} MB for 500 000"
fi
# every frame was played: 500 000 frames, a tenth of one percent of them to the cars
in_total=$(python3 -c '
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
print(sum(r["framesIn"] for r in rows), sum(r["framesOut"] for r in rows), len(rows))' long.json)
check "a long record: every frame played, per car" "499500 500 4" "$in_total"

# 3. A pipe is refused with a sentence before it is read: a replay reads its file twice.
mkfifo pipe.jsonl
timeout 60 $PITWALL replay pipe.jsonl 2>pipe.err >/dev/null
check "a pipe: exit status" 2 "$?"
contains "a pipe: the sentence" "pipe.jsonl is not a file (a pipe or a device); a replay reads its record twice" "$(cat pipe.err)"

[ "$FAILURES" -eq 0 ]
