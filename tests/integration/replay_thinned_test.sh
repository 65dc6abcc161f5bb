# A record thinned the way a real car thins its position updates (../shared/realdata: at race
# speed a curve sends no 0x27, a straight two or three; a 0x29 at every boundary) loses no lap in
# `pitwall replay --summary`: the transitions carry each car along the record's layout (or
# --track) to the line. Several seeds, from dropping the curves' 0x27s at speed and a quarter of
# the rest to dropping every 0x27 after the first of each car. A record without a layout and
# without --track has no map: its laps come from the start piece's own reports (two laps seen),
# then from the count of pieces a lap has.
source "$(dirname "$0")/lib.sh"

LAPS=4 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --cars 4 --seed 7 \
  --record "$TMP/full.rec" >/dev/null 2>"$TMP/run.err" || fail "the grand prix: $(tail -3 "$TMP/run.err")"

# thin IN OUT SEED LOST [KEEP_LAYOUT]: drops every 0x27 from a curve at more than 500 mm/s, then
# the share LOST of the others (but the first 0x27 of each car, which places it on the map)
thin() {
  python3 - "$@" <<'PY'
import json, random, sys
src, dst, seed, lost = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
keep_layout = len(sys.argv) > 5 and sys.argv[5] == "layout"
curves = {17, 18, 20, 23, 24, 27}
rng = random.Random(seed)
seen = set()
with open(src) as f, open(dst, "w") as out:
    for line in f:
        frame = json.loads(line)
        if "hex" not in frame:  # the race's own lines (docs/cli.md "Record format"): kept
            out.write(line)
            continue
        if not keep_layout:
            frame.pop("layout", None)
        b = bytes.fromhex(frame["hex"])
        if frame["dir"] == "rx" and len(b) > 9 and b[1] == 0x27:
            piece, speed = b[3], int.from_bytes(b[8:10], "little")
            first = frame["car"] not in seen
            seen.add(frame["car"])
            if not first and ((piece in curves and speed > 500) or rng.random() < lost):
                continue
        out.write(json.dumps(frame) + "\n")
PY
}
laps() { $PITWALL replay "$1" --json "${@:2}" 2>/dev/null | python3 -c '
import json, sys
print(" ".join(str(json.loads(l)["laps"]) for l in sys.stdin))'; }
count27() { grep -c '"hex": \?"[0-9a-f][0-9a-f] 27 ' "$1"; }

full=$(laps "$TMP/full.rec")
[ -n "$full" ] && echo "ok: the full record's laps: $full" || fail "no summary of the full record"
check "every car drove laps" "" "$(echo "$full" | tr ' ' '\n' | grep -x 0)"

for seed in 1 2 3 4 5; do
  thin "$TMP/full.rec" "$TMP/thin.rec" $seed 0.25 layout
  check "seed $seed, curves at speed and a quarter of the rest lost: laps as the full record" \
    "$full" "$(laps "$TMP/thin.rec")"
done
thin "$TMP/full.rec" "$TMP/bare.rec" 1 1.0 layout
echo "ok: transitions only: $(count27 "$TMP/bare.rec") of $(count27 "$TMP/full.rec") position updates kept"
check "transitions only (one 0x27 a car): laps as the full record" "$full" "$(laps "$TMP/bare.rec")"

# no layout in the record: --track gives the map
thin "$TMP/full.rec" "$TMP/nolayout.rec" 2 0.25
check "no layout, --track oval: laps as the full record" "$full" \
  "$(laps "$TMP/nolayout.rec" --track oval)"
out=$($PITWALL replay "$TMP/nolayout.rec" --summary --track nowhere 2>&1); rc=$?
check "a --track that is no layout: exit status" 2 "$rc"
contains "a --track that is no layout: says so" "nowhere" "$out"

finish
