# `pitwall track verify` on hostile SVGs (issue 33, docs/cli.md "track verify", docs/safety.md
# "Hostile input"): an entity bomb, a blur filter that takes minutes, a 100 MB file, a document
# too large to hold — each refused with a sentence and status 2, in bounded memory and time: the
# whole process tree's peak resident memory is measured (a parent's view of its reaped
# descendants), and a generous timeout fails the test only if a refusal hangs.
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 2

# run_peak OUT CMD…: runs CMD with its stderr in OUT; prints "STATUS PEAK_MB" (PEAK_MB: the
# largest resident set of CMD and every process it started). 120 s at most (status 124).
run_peak() {
  local out=$1
  shift
  python3 - "$out" "$@" <<'PY'
import resource, subprocess, sys
with open(sys.argv[1], "wb") as err:
    try:
        rc = subprocess.run(sys.argv[2:], stdout=subprocess.DEVNULL, stderr=err, timeout=120).returncode
    except subprocess.TimeoutExpired:
        rc = 124
print(rc, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)
PY
}

# bounded NAME OUT LIMIT_MB STATUS_AND_PEAK: status 2 and a peak under LIMIT_MB
bounded() {
  local status=${4% *} peak=${4#* }
  check "$1: exit status" 2 "$status"
  if ((peak < $3)); then echo "ok: $1: peak memory ${peak} MB, under $3 MB"; else
    fail "$1: peak memory ${peak} MB, expected under $3 MB"; fi
}

$PITWALL track print S:60,len=300 --out piece.svg 2>/dev/null || fail "print the piece"
head -c 400 piece.svg | grep -q '^<svg\|<?xml' || fail "the piece SVG starts as expected"
# every hostile file below is this piece with something added, so its metadata is whole and
# only the addition can be what is refused
split_at_svg() { python3 -c '
import sys
text = open("piece.svg").read()
at = text.index("<svg")
sys.stdout.write(text[:at] if sys.argv[1] == "head" else text[at:])' "$1"; }

# 1. An entity bomb: ten levels of ten, 10¹⁰ expansions of a few bytes, used 20 000 times.
{
  echo '<?xml version="1.0"?>'
  echo '<!DOCTYPE svg ['
  echo '<!ENTITY e0 "pitwall">'
  for i in $(seq 1 9); do
    printf '<!ENTITY e%d "' "$i"; for _ in $(seq 10); do printf '&e%d;' $((i - 1)); done; echo '">'
  done
  echo ']>'
  split_at_svg tail | python3 -c '
import sys
text = sys.stdin.read()
at = text.rindex("</svg>")
sys.stdout.write(text[:at] + "<text>" + "&e9;" * 20000 + "</text>" + text[at:])'
} >bomb.svg
res=$(run_peak bomb.err $PITWALL track verify bomb.svg)
bounded "an entity bomb" bomb.err 200 "$res"
contains "an entity bomb: the sentence" "bomb.svg declares XML entities (<!ENTITY …> in its DOCTYPE)" "$(cat bomb.err)"
# under a memory limit too it is a sentence, never an abort (the review's SIGABRT)
prlimit --as=$((1024 * 1024 * 1024)) $PITWALL track verify bomb.svg 2>limited.err
check "an entity bomb under a 1 GB address space: exit status" 2 "$?"
contains "an entity bomb under a limit: the sentence" "declares XML entities" "$(cat limited.err)"

# 2. A blur filter that takes minutes to draw (each band of the page blurs the whole page, 200
# times): stopped at the CPU time allowed.
python3 - <<'PY'
text = open("piece.svg").read()
at = text.rindex("</svg>")
blur = '<filter id="b" x="-50%" y="-50%" width="200%" height="200%"><feGaussianBlur stdDeviation="40"/></filter>'
rects = "".join('<rect x="0" y="0" width="324" height="208" fill="#%06x" filter="url(#b)" opacity="0.01"/>' % (i * 9973 % 0xffffff) for i in range(200))
open("blur.svg", "w").write(text[:at] + "<defs>" + blur + "</defs>" + rects + text[at:])
PY
res=$(run_peak blur.err $PITWALL track verify blur.svg --draw-seconds 2)
bounded "a blur filter" blur.err 800 "$res"
contains "a blur filter: the sentence" "the SVG took more than 2 s to draw: blur.svg is not read" "$(cat blur.err)"
contains "a blur filter: what to do" "allow more with --draw-seconds" "$(cat blur.err)"

# 3. A 100 MB file (made here, never committed): refused by its size before a byte is read.
python3 -c '
import sys
text = open("piece.svg").read()
at = text.rindex("</svg>")
with open("big.svg", "w") as out:
    out.write(text[:at])
    chunk = "<!-- " + "x" * (1 << 20) + " -->\n"
    for _ in range(100):
        out.write(chunk)
    out.write(text[at:])'
res=$(run_peak big.err $PITWALL track verify big.svg)
bounded "a 100 MB SVG" big.err 100 "$res"
contains "a 100 MB SVG: the sentence" "big.svg is $(stat -c %s big.svg) bytes" "$(cat big.err)"
contains "a 100 MB SVG: the limit" "bytes, more than the 16777216 a piece SVG can be" "$(cat big.err)"

# 4. A document within the size cap whose drawing needs more memory than allowed (a quarter of a
# million elements): the drawing process ends at its limit, the command says which.
python3 - <<'PY'
text = open("piece.svg").read()
at = text.rindex("</svg>")
rects = '<rect x="1" y="1" width="1" height="1"/>' * 250000
open("many.svg", "w").write(text[:at] + "<g>" + rects + "</g>" + text[at:])
PY
res=$(run_peak many.err $PITWALL track verify many.svg --draw-mb 32)
bounded "an SVG too large to draw in 32 MB" many.err 400 "$res"
contains "too large to draw: the sentence" "the SVG took more than 32 MB to draw: many.svg is not read" "$(cat many.err)"
cat bomb.err blur.err big.err many.err  # the sentences, for whoever reads the log

# The piece itself still reads back as designed within the default limits.
out=$($PITWALL track verify piece.svg 2>&1)
check "the piece itself: exit status" 0 "$?"
contains "the piece itself: the verdict" "piece.svg: OK: S:60,len=300 (piece 60)" "$out"

[ "$FAILURES" -eq 0 ]
