# Printing pieces and reading the printout back (docs/cli.md "track print", "track verify"):
# the PDF has the pages and paper it should and its ruler is 100 mm at 300 dpi; the SVG reads back
# as designed, and not when a stroke is gone or it was scaled; bad input is refused with a
# sentence and status 2, never a crash.
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 2

# 1. PDF: pages and paper. S:60,len=300 is a 324 × 208 mm sheet; a page's printable part is
# its size less 5 mm margins and a 14 mm band (label and ruler); neighbouring tiles share 5 mm.
pdf_pages() { pdfinfo "$1" | sed -n 's/^Pages: *//p'; }
pdf_size() { pdfinfo "$1" | sed -n 's/^Page size: *//p'; }
out=$($PITWALL track print S:60,len=300 --out a4.pdf 2>&1); rc=$?
check "print a PDF: exit status" 0 "$rc"
contains "says what it wrote" "wrote a4.pdf: 1 piece on 2 A4 pages" "$out"
check "A4 portrait: 2 tiles side by side" 2 "$(pdf_pages a4.pdf)"
check "A4 portrait: page size" "595.276 x 841.89 pts (A4)" "$(pdf_size a4.pdf)"
$PITWALL track print S:60,len=300 --out a4l.pdf --landscape 2>/dev/null
check "A4 landscape: 2 × 2 tiles" 4 "$(pdf_pages a4l.pdf)"
check "A4 landscape: page size" "841.89 x 595.276 pts (A4)" "$(pdf_size a4l.pdf)"
$PITWALL track print S:60,len=300 --out a3.pdf --paper a3 2>/dev/null
check "A3 portrait: 2 tiles" 2 "$(pdf_pages a3.pdf)"
check "A3 portrait: page size" "841.89 x 1190.55 pts (A3)" "$(pdf_size a3.pdf)"
$PITWALL track print S:60,len=300 --out a3l.pdf --paper a3 --landscape 2>/dev/null
check "A3 landscape: the whole piece on 1 page" 1 "$(pdf_pages a3l.pdf)"
check "A3 landscape: page size" "1190.55 x 841.89 pts (A3)" "$(pdf_size a3l.pdf)"
# every piece of a layout file, in order: start is two pieces
printf 'start S:36 L:17 L:17 S:36 S:36 L:17 L:17 # an oval\n' >oval.txt
out=$($PITWALL track print oval.txt --out oval.pdf 2>&1); rc=$?
check "print a layout file: exit status" 0 "$rc"
contains "a layout file: every piece" "wrote oval.pdf: 9 pieces on" "$out"
contains "the PDF's pages are what it says" "on $(pdf_pages oval.pdf) A4 pages" "$out"
# --custom: only the pieces a starter kit does not have (the hairpin's 9 of 12)
out=$($PITWALL track print "$SRC/examples/tracks/hairpin.layout" --custom --out custom.pdf 2>&1); rc=$?
check "print --custom: exit status" 0 "$rc"
contains "print --custom: the custom pieces only" "wrote custom.pdf: 9 pieces on" "$out"

# 2. the ruler on a page rasterized at 300 dpi: 100 mm = 1181 px (± 3). Rows that cross only the
# 10 mm ticks show 11 evenly spaced dark runs; from the first to the last is the ruler.
pdftoppm -r 300 -gray -f 2 -l 2 a4.pdf page
ruler=$(python3 - page-2.pgm <<'EOF'
import sys
data = open(sys.argv[1], "rb").read()
parts = data.split(maxsplit=4)
assert parts[0] == b"P5", parts[0]
w, h, pixels = int(parts[1]), int(parts[2]), parts[4]
found = []
for y in range(h - 300, h):  # the bottom 25 mm
    row = pixels[y * w:(y + 1) * w]
    runs, start = [], None
    for x in range(w):
        dark = row[x] < 128
        if dark and start is None:
            start = x
        elif not dark and start is not None:
            runs.append((start + x - 1) / 2)
            start = None
    if len(runs) != 11:
        continue
    gaps = [b - a for a, b in zip(runs, runs[1:])]
    if all(abs(g - 118.1) < 4 for g in gaps):
        found.append(runs[-1] - runs[0])
print(round(sorted(found)[len(found) // 2]) if found else "no ruler")
EOF
)
if [[ "$ruler" =~ ^[0-9]+$ ]] && ((ruler >= 1178 && ruler <= 1184)); then
  echo "ok: the ruler is 100 mm at 300 dpi ($ruler px)"
else
  fail "the ruler at 300 dpi: expected 1181 ± 3 px, got [$ruler]"
fi

# 3. SVG: written whole at 1:1, read back as designed in both directions on every row
out=$($PITWALL track print S:60,len=300 --out piece.svg 2>&1); rc=$?
check "print an SVG: exit status" 0 "$rc"
contains "an SVG in mm" 'width="324mm" height="208mm" viewBox="0 0 324 208"' "$(head -c 400 piece.svg)"
out=$($PITWALL track verify piece.svg 2>verify.err); rc=$?
check "verify the SVG: exit status" 0 "$rc"
# a good piece: the verdict alone on stdout, what was read under which conditions on stderr
check "verify: the verdict, one line" \
  "piece.svg: OK: S:60,len=300 (piece 60), 64 section readings on 16 rows in both directions all decode to the design" "$out"
check "verify: how it read, one line" \
  "reading piece.svg at 300 dpi: S:60,len=300 (piece 60), blur 0.25 mm, misalignment up to 0.5 mm" "$(cat verify.err)"
for flag in --verbose -v; do
  out=$($PITWALL track verify piece.svg "$flag" 2>/dev/null); rc=$?
  check "verify $flag: exit status" 0 "$rc"
  contains "verify $flag: every row forward" "piece.svg: row 16 forward:  OK, 2 sections" "$out"
  contains "verify $flag: every row backward" "piece.svg: row 1 backward: OK, 2 sections" "$out"
  check "verify $flag: a line per row and direction, then the verdict" 33 "$(printf '%s\n' "$out" | wc -l)"
done
# a curve, and the start pair (two files)
# a right curve is its left curve's piece laid the other way round: the same sheet
$PITWALL track print L:17 --out left.svg 2>/dev/null
$PITWALL track print R:17 --out right.svg 2>/dev/null
check "a right curve prints as its left curve" yes "$(cmp -s left.svg right.svg && echo yes)"
$PITWALL track print L:61,r=400,deg=45 --out curve.svg 2>/dev/null
out=$($PITWALL track verify curve.svg 2>&1); rc=$?
check "verify a custom curve" 0 "$rc"
out=$($PITWALL track print start --out start.svg 2>&1)
contains "several pieces: a file each" "wrote start-2.svg: start (piece 33)" "$out"
$PITWALL track verify start-1.svg >/dev/null 2>&1
check "verify start piece 34" 0 "$?"

# a stock piece by its id alone, as `track list` lists it: 40 is S:40, 17 L:17, 34 the start's first
out=$($PITWALL track print 40 --out s40.svg 2>&1); rc=$?
check "print a stock piece by its id: exit status" 0 "$rc"
check "print 40: the stock straight" "wrote s40.svg: S:40 (piece 40)" "$out"
$PITWALL track print S:40 --out s40-token.svg 2>/dev/null
check "print 40 is print S:40" yes "$(cmp -s s40.svg s40-token.svg && echo yes)"
check "print 17: the stock curve" "wrote c17.svg: L:17 (piece 17)" "$($PITWALL track print 17 --out c17.svg 2>&1)"
check "print 34: the start's first piece" "wrote s34.svg: start (piece 34)" "$($PITWALL track print 34 --out s34.svg 2>&1)"
$PITWALL track verify s34.svg >/dev/null 2>&1
check "verify a start piece printed by its id" 0 "$?"
out=$($PITWALL track print 40 --out s40.pdf 2>&1)
contains "print 40 to a PDF" "wrote s40.pdf: 1 piece on" "$out"

# 4. tampered: one stroke gone (the first stroke of row 1, piece side), or printed 3 % larger
python3 - piece.svg nostroke.svg <<'EOF'
import re, sys
svg = open(sys.argv[1]).read()
paths = list(re.finditer(r' d="([^"]*)"', svg))
code = max(paths, key=lambda m: m.group(1).count("M"))  # the lines and strokes: one path
subpaths = re.findall(r"M[^M]*", code.group(1))
del subpaths[1]  # [0] is row 1's line, [1] its first stroke
svg = svg[:code.start(1)] + "".join(subpaths) + svg[code.end(1):]
open(sys.argv[2], "w").write(svg)
EOF
out=$($PITWALL track verify nostroke.svg 2>&1); rc=$?
check "a stroke removed: exit status" 1 "$rc"
contains "a stroke removed: names row and section" "nostroke.svg: row 1 forward:  section 1 (piece 60, location 0)" "$out"
contains "a stroke removed: backward too" "nostroke.svg: row 1 backward: section 1 (piece 60, location 0)" "$out"
contains "a stroke removed: the verdict" "nostroke.svg: FAILED" "$out"
# only the rows that fail (row 1, both ways), the stderr line and the verdict
check "a stroke removed: the failing rows alone" 4 "$(printf '%s\n' "$out" | wc -l)"
case "$out" in *"OK, 2 sections"*) fail "a good row listed without --verbose: $out" ;; *) echo "ok: no good row listed" ;; esac
sed 's/width="324mm" height="208mm"/width="333.72mm" height="214.24mm"/' piece.svg >big.svg
out=$($PITWALL track verify big.svg 2>&1); rc=$?
check "scaled by 3 %: exit status" 1 "$rc"
contains "scaled by 3 %: says so" "row 4 forward:  strokes 3.0 % further apart than designed: the page was scaled; print at actual size" "$out"
sed 's/width="324mm" height="208mm"/width="314.28mm" height="201.76mm"/' piece.svg >small.svg
out=$($PITWALL track verify small.svg 2>&1); rc=$?
check "scaled to 97 %: exit status" 1 "$rc"
contains "scaled to 97 %: says so" "strokes 3.0 % closer together than designed" "$out"

# 5. bad input: status 2, one sentence naming the thing, no crash
bad() {  # NAME NEEDLE ARGS...: exit status 2 and the sentence
  local name=$1 needle=$2
  shift 2
  out=$($PITWALL track "$@" 2>&1); rc=$?
  check "$name: exit status" 2 "$rc"
  contains "$name: says why" "$needle" "$out"
}
bad "verify a missing file" "cannot read missing.svg: No such file or directory" verify missing.svg
head -c 3000 /dev/urandom >garbage.svg
bad "verify garbage" "garbage.svg is not a piece SVG written by \`pitwall track print\`" verify garbage.svg
$PITWALL track show oval --svg show.svg >/dev/null 2>&1
bad "verify an SVG that is no piece" "show.svg is not a piece SVG written by" verify show.svg
sed 's/<svg /<svg <</' piece.svg >broken.svg
bad "verify a broken SVG" "broken.svg is not an SVG librsvg can read" verify broken.svg
sed 's/token="S:60,len=300"/token="Q:999"/' piece.svg >badtoken.svg
bad "verify an SVG naming no piece" "badtoken.svg names the piece 'Q:999'" verify badtoken.svg
sed 's/width="324mm" height="208mm"/width="90000mm" height="90000mm"/' piece.svg >huge.svg
bad "verify a huge SVG" "use a lower --dpi" verify huge.svg
# wider than cairo's 32767 px at an allowed --dpi: refused, not a crash (review of issue 21)
$PITWALL track print S:60,len=736 --out long.svg 2>/dev/null
bad "verify a sheet too wide at 1100 dpi" "use a lower --dpi" verify long.svg --dpi 1100
sed 's/width="[0-9.]*mm" height="[0-9.]*mm"/width="1e30mm" height="1e-30mm"/' piece.svg >thin.svg
out=$($PITWALL track verify thin.svg 2>&1); rc=$?
check "verify an absurd sheet: exit status" 2 "$rc"
bad "verify --dpi 0" "--dpi" verify piece.svg --dpi 0
bad "verify --blur nan" "--blur nan is not a number" verify piece.svg --blur nan
bad "print a bad token" "Q:9" print Q:9 --out q.pdf
bad "print a stock id pitwall has no shape for" \
  "piece 10 is Anki's intersection, which pitwall has no shape for: it lays out, draws and prints the start pair (34, 33), straights (36, 39, 40, 48, 51) and curves (17, 18, 20, 23, 24, 27)" print 10 --out i.svg
bad "print an id that is no stock piece" \
  "60 is not one of Anki's stock pieces: they are the start pair (34, 33), straights (36, 39, 40, 48, 51) and curves (17, 18, 20, 23, 24, 27); a piece of your own needs its shape, such as S:60,len=300 or L:60,r=400,deg=45" print 60 --out c.svg
bad "print an id beyond the code's 7 bits" "such as S:60,len=300" print 200 --out c.svg
bad "print onto unknown paper" "unknown paper 'letter': use a4 or a3" print S --paper letter --out s.pdf
bad "print to neither PDF nor SVG" "--out 's.png' names neither a .pdf nor a .svg file" print S --out s.png
bad "print into a missing folder" "cannot write no/such/s.svg" print S --out no/such/s.svg
bad "print into a missing folder (PDF)" "cannot write no/such/s.pdf" print S --out no/such/s.pdf
# the print module missing or broken: a sentence and status 2, never a crash
out=$(PITWALL_PRINT_MODULE="$TMP/none.so" $PITWALL track print S --out m.pdf 2>&1); rc=$?
check "print without its module: exit status" 2 "$rc"
contains "print without its module: says so" "the print module cannot be loaded (looked for $TMP/none.so)" "$out"
cp "$(dirname "$PITWALL")/lib/pitwall/pitwall_print.so" mod.so
out=$(PITWALL_PRINT_MODULE=mod.so $PITWALL track print S --out rel.svg 2>&1); rc=$?
check "print with \$PITWALL_PRINT_MODULE relative to the folder: exit status" 0 "$rc"
contains "print with \$PITWALL_PRINT_MODULE relative to the folder: wrote it" "wrote rel.svg" "$out"
head -c 2000 /dev/urandom >bad.so
out=$(PITWALL_PRINT_MODULE="$TMP/bad.so" $PITWALL track verify piece.svg 2>&1); rc=$?
check "verify with a broken module: exit status" 2 "$rc"
contains "verify with a broken module: says so" "pitwall track verify: the print module cannot be loaded (" "$out"
contains "verify with a broken module: names the variable" "set \$PITWALL_PRINT_MODULE to the pitwall_print.so of this build, or unset it" "$out"
bad "print --custom of stock pieces" "oval.txt has no custom pieces" print oval.txt --custom --out c.pdf

# 6. --code: calibrated strokes, recorded in the SVG and read back with them; the PDF says so
out=$($PITWALL track print S:60,len=300 --code thick=1.5 --code stroke_pitch=16 --out code.svg 2>&1); rc=$?
check "print --code: exit status" 0 "$rc"
contains "print --code: the SVG records the dimensions" 'code-thick-mm="1.5000"' "$(grep -o 'code-thick-mm="[^"]*"' code.svg)"
out=$($PITWALL track verify code.svg 2>&1); rc=$?
check "verify a --code print: exit status" 0 "$rc"
contains "verify a --code print: reads with the file's dimensions" "code stroke_pitch 16.00 mm, thick 1.50 mm" "$out"
contains "verify a --code print: the verdict" "code.svg: OK: S:60,len=300 (piece 60), 64 section readings" "$out"
out=$($PITWALL track verify code.svg --code stroke_pitch=16.5 2>&1); rc=$?
check "verify --code over the file's: exit status" 1 "$rc"
contains "verify --code over the file's: the spacing" "strokes 3.0 % closer together than designed" "$out"
out=$($PITWALL track print S:60,len=300 --code thick=1.4 --out code.pdf 2>&1); rc=$?
check "print a PDF with --code: exit status" 0 "$rc"
contains "print a PDF with --code: stderr says which" "code: thick 1.40 mm" "$out"
contains "print a PDF with --code: the page's label says which" "code: thick 1.40 mm" "$(pdftotext code.pdf - 2>/dev/null)"
# an SVG written before the dimensions were recorded reads with the defaults
sed 's/ code-[a-z-]*-mm="[^"]*"//g' piece.svg >old.svg
check "an old SVG has no code dimensions" 0 "$(grep -c 'code-' old.svg)"
$PITWALL track verify old.svg >/dev/null 2>&1
check "verify an old SVG: the defaults" 0 "$?"
bad "print --code with an unknown name" "--code thikc=1.4: unknown code dimension 'thikc' (did you mean thick?)" print S --code thikc=1.4 --out s.svg
bad "print --code rows" "--code rows=8: rows decides the location ids the simulator reports, so it stays as it is" print S --code rows=8 --out s.svg
bad "print --code nan" "--code thick=nan: 'nan' is not a number; give thick in mm" print S --code thick=nan --out s.svg
bad "print --code too wide" "--code wide=2.6: a wide stroke reaches 4.04 mm from its line" print S --code wide=2.6 --out s.svg
bad "verify --code 0" "--code gap=0: gap must be more than 0" verify piece.svg --code gap=0
sed 's/code-thick-mm="[^"]*"/code-thick-mm="x"/' piece.svg >badcode.svg
bad "verify an SVG with a bad code dimension" "badcode.svg is not a piece SVG written by \`pitwall track print\` (its pitwall piece metadata has no number code-thick-mm)" verify badcode.svg

finish
