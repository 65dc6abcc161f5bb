# Mapping any loop from what real cars sent (docs/racing.md "Mapping any loop"): each of the
# eight okoeth runs — one car on four lanes of a 6-piece oval with no start/finish piece, at 250
# and 750 mm/s, about two laps each, lane 4 at 250 without one position update — replayed into
# examples/map_track.lua (track.learn) maps to the same six pieces, right curves and straights in
# the oval's order (17 → 18 → 40 → 18 → 23 → 39, tests/realdata/README.md), every id it names at
# its place in that order.
source "$(dirname "$0")/lib.sh"
REAL=$SRC/tests/realdata/okoeth

for capture in "$REAL"/lane?_speed???.txt; do
  run=$(basename "$capture" .txt)
  WATCH=1 $PITWALL replay "$capture" --script "$SRC/examples/map_track.lua" >"$TMP/$run.out" \
    2>"$TMP/$run.err"
  check "$run: exit status" 0 "$?"
  layout=$(sed -n 's/^layout: //p' "$TMP/$run.out")
  verdict=$(python3 - "$layout" <<'PY'
import sys
oval = [("R", 17), ("R", 18), ("S", 40), ("R", 18), ("R", 23), ("S", 39)]
words = sys.argv[1].split()
got = [(w.split(":")[0], int(w.split(":")[1]) if ":" in w else None) for w in words]
if len(got) != len(oval):
    print(f"{len(got)} pieces: {sys.argv[1]!r}")
    sys.exit()
for r in range(len(oval)):  # some rotation of the oval fits every piece
    turned = oval[r:] + oval[:r]
    if all(g[0] == o[0] and (g[1] is None or g[1] == o[1]) for g, o in zip(got, turned)):
        print("ok")
        sys.exit()
print(f"no rotation of the oval fits {sys.argv[1]!r}")
PY
)
  check "$run: the oval's six pieces ($layout)" ok "$verdict"
  contains "$run: said to have no start piece" "no start piece: laps where the scan began" \
    "$(cat "$TMP/$run.out")"
done
# lane 4 at 250 mm/s sent no position update: its map is shapes alone
check "lane4_speed250: no id known, the shapes right" "R R S R R S" \
  "$(sed -n 's/^layout: //p' "$TMP/lane4_speed250.out")"

finish
