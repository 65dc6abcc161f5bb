# Showing and listing tracks (docs/cli.md "track show", "track list"): the SVG of `track show
# --svg` shows the whole track in a browser window of any size (in Chromium, as a user opens the
# file), and `track list` names the built-in layouts and Anki's stock pieces with their ids.
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 2

# 1. The SVG scales to the window: its size is the window's (100 %), its viewBox the drawing's
# bounds in mm (the dark background rect), so a browser draws all of it, letterboxed.
out=$($PITWALL track show oval --svg oval.svg 2>&1); rc=$?
check "track show --svg: exit status" 0 "$rc"
contains "track show --svg: says what it wrote" "wrote oval.svg" "$out"
root=$(head -c 300 oval.svg)
contains "the SVG fills the window it is shown in" 'width="100%" height="100%"' "$root"
check "the viewBox is the drawing's bounds in mm" "ok" "$(python3 - oval.svg <<'EOF'
import re, sys
svg = open(sys.argv[1]).read()
box = [float(v) for v in re.search(r'<svg [^>]*viewBox="([^"]*)"', svg).group(1).split()]
rect = re.search(r'<rect x="([^"]*)" y="([^"]*)" width="([^"]*)" height="([^"]*)"', svg)
print("ok" if box == [float(v) for v in rect.groups()] and 1900 < box[2] < 2100 else box)
EOF
)"
$PITWALL track show oval --svg - 2>/dev/null >stdout.svg
check "--svg - writes the same document to stdout" yes "$(cmp -s oval.svg stdout.svg && echo yes)"

# In Chromium, at two window sizes: the dark background — the whole drawing — lies inside the
# window with the drawing's proportions (a fixed size larger than the window showed one corner,
# the window full of background and scroll bars).
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
if [ -x "$CHROMIUM" ]; then
  for size in 800,600 1280,800; do
    timeout 60 "$CHROMIUM" --headless=new --no-sandbox --disable-gpu --hide-scrollbars \
      --window-size="$size" --screenshot="$PWD/shot.png" "file://$PWD/oval.svg" >/dev/null 2>&1
    result=$(python3 - shot.png oval.svg <<'EOF'
import re, struct, sys, zlib
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n"
pos, chunks = 8, {}
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    chunks.setdefault(kind, []).append(data[pos + 8:pos + 8 + n])
    pos += 12 + n
w, h, depth, colour = struct.unpack(">IIBB", chunks[b"IHDR"][0][:10])
assert depth == 8 and colour in (2, 6), (depth, colour)
bpp = 3 if colour == 2 else 4
raw = zlib.decompress(b"".join(chunks[b"IDAT"]))
rows, prev, stride = [], bytearray(w * bpp), w * bpp
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        p = a + b - c
        pred = [0, a, b, (a + b) // 2,
                a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else b if abs(p - b) <= abs(p - c) else c][f]
        line[i] = (line[i] + pred) & 0xFF
    rows.append(line)
    prev = line
def dark(x, y):  # the drawing's background, #1b1f24
    r, g, b = rows[y][x * bpp:x * bpp + 3]
    return abs(r - 0x1b) < 6 and abs(g - 0x1f) < 6 and abs(b - 0x24) < 6
xs = [x for x in range(w) if dark(x, h // 2)]
ys = [y for y in range(h) if dark(w // 2, y)]
box = [float(v) for v in re.search(r'viewBox="([^"]*)"', open(sys.argv[2]).read()).group(1).split()]
shown = (xs[-1] - xs[0] + 1) / (ys[-1] - ys[0] + 1)
whole = (xs[0] > 0 or ys[0] > 0) and abs(shown / (box[2] / box[3]) - 1) < 0.03
print("ok" if whole else f"not whole: background {xs[0]}..{xs[-1]} x {ys[0]}..{ys[-1]} of {w}x{h}")
EOF
)
    check "Chromium at $size shows the whole track" ok "$result"
  done
else
  fail "no Chromium at $CHROMIUM to open the SVG in; install chromium (./dev test does) or set CHROMIUM"
fi

# 2. track list: the layouts with their pieces, Anki's pieces by id and kind.
out=$($PITWALL track list 2>&1); rc=$?
check "track list: exit status" 0 "$rc"
contains "track list: the oval" "  oval     9 pieces, lap 4.00 m, floor 1.87 m × 0.75 m: start S:36 L:17 L:18 S:39 S:40 L:20 L:23" "$out"
contains "track list: the kidney" "  kidney " "$out"
contains "track list: the long oval" "  long " "$out"
contains "track list: the start pair" "  34  start-long   340 mm, up to the finish line" "$out"
contains "track list: a stock straight" "  40  straight     560 mm" "$out"
contains "track list: a stock curve" "  17  curve        90°, centre radius 280 mm" "$out"
contains "track list: the pieces pitwall has no shape for" "  10  intersection no shape in pitwall" "$out"
# every id it lists as printable prints (track print ID), and every layout it lists shows
for id in $(printf '%s\n' "$out" | sed -n 's/^  \([0-9][0-9]*\)  *[a-z-]*  *[0-9].*/\1/p'); do
  $PITWALL track print "$id" --out "piece-$id.svg" >/dev/null 2>&1 || fail "track print $id, as track list lists it"
done
check "track list lists 13 printable pieces" 13 "$(ls piece-*.svg | wc -l)"
for name in $(printf '%s\n' "$out" | sed -n 's/^  \([a-z][a-z]*\)  *[0-9]* pieces.*/\1/p'); do
  $PITWALL track show "$name" >/dev/null 2>&1 || fail "track show $name, as track list lists it"
done
# and bash completes it
$PITWALL completion bash >pitwall.bash
check "bash completes track list" "list" "$(bash -c 'source pitwall.bash; COMP_WORDS=(pitwall track l)
  COMP_CWORD=2; _pitwall; printf "%s\n" "${COMPREPLY[@]}"')"

finish
