#!/usr/bin/env bash
# The race view in a real browser (docs/view.md): a grand prix with --view on a free port, the page
# loaded in headless Chromium and in Firefox ESR (tests/view/browser_check.mjs, puppeteer-core pinned by
# tests/view/package-lock.json): track, 4 moving cars, leaderboard, charts; then Ctrl-C to the
# engine and the open page says "engine gone". Screenshots in ./view_test_artifacts/.
source "$(dirname "$0")/lib.sh"

pid=""
cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT

# Real parts: no browser or no node is a failure, not a skip (./dev test installs them).
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
FIREFOX=${FIREFOX:-/usr/bin/firefox-esr}
command -v node >/dev/null || { echo "FAIL: node is missing; install nodejs (./dev test does)"; exit 1; }
command -v npm >/dev/null || { echo "FAIL: npm is missing; install npm (./dev test does)"; exit 1; }
[ -x "$CHROMIUM" ] || { echo "FAIL: no Chromium at $CHROMIUM; install chromium (./dev test does) or set CHROMIUM"; exit 1; }
[ -x "$FIREFOX" ] || { echo "FAIL: no Firefox at $FIREFOX; install firefox-esr (./dev test does) or set FIREFOX"; exit 1; }

# puppeteer-core, installed once in the build tree (again when the lockfile changes).
CHECK="$PWD/view_browser_check"
mkdir -p "$CHECK"
if ! cmp -s "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock" ||
   [ ! -d "$CHECK/node_modules/puppeteer-core" ]; then
  cp "$SRC/tests/view/package.json" "$SRC/tests/view/package-lock.json" "$CHECK/"
  if ! (cd "$CHECK" && timeout 300 npm ci --no-audit --no-fund --loglevel=error); then
    echo "FAIL: npm ci of tests/view (puppeteer-core) in $CHECK"
    exit 1
  fi
  cp "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock"
fi
# Beside its node_modules, so that `import "puppeteer-core"` resolves.
cp "$SRC/tests/view/browser_check.mjs" "$CHECK/"

ART="$PWD/view_test_artifacts"
mkdir -p "$ART"
rm -f "$ART"/view-*.png

# in_browser NAME BROWSER-OPTION PATH: a long race (it must not end by itself before the check is
# done), real time, any free port; the page checked in that browser, then SIGINT to pitwall and
# the open page says "engine gone"; an engine started again on the same address, and the page
# says "live" by itself with the cars back. Screenshots $ART/view-NAME.png and view-NAME-gone.png.
in_browser() {
  local name=$1 option=$2 path=$3
  # Emptied here, not by the redirection below: that happens in the background child, after
  # wait_for may already have read the previous run's address from the old file.
  : > "$TMP/out"
  : > "$TMP/err"
  LAPS=50 "$PITWALL" run "$SRC/examples/grand_prix.lua" --view 127.0.0.1:0 \
    > "$TMP/out" 2> "$TMP/err" &
  pid=$!
  if ! wait_for "$TMP/err" '^view: http://127\.0\.0\.1:[0-9]+/' 20; then
    fail "pitwall printed no 'view: http://127.0.0.1:PORT/' line within 20 s; its stderr:"
    sed 's/^/  | /' "$TMP/err"
    finish
  fi
  url=$(grep -oE '^view: http://127\.0\.0\.1:[0-9]+/' "$TMP/err" | head -1 | sed 's/^view: //')
  echo "ok: view at $url ($name)"
  local addr=${url#http://}
  addr=${addr%/}

  # /api/state answers the whole state as JSON (the page itself uses /ws).
  state=$(timeout 20 node -e '
    fetch(process.argv[1] + "api/state").then((r) => r.json()).then((s) => {
      console.log(`${s.type} track=${s.track ? s.track.name : null} cars=${s.cars.length}`);
    }).catch((e) => { console.log(`error ${e.message}`); process.exit(1); });' "$url")
  check "/api/state is the whole state" "state track=oval cars=4" "$state"

  timeout -k 5 180 node "$CHECK/browser_check.mjs" "$url" "$ART/view-$name.png" \
    --expect-cars 4 --kill "$pid" --timeout 40 "$option" "$path" \
    --restart "$(printf '%q ' "$PITWALL" run "$SRC/examples/grand_prix.lua" --view "$addr")"
  check "$name: browser check exit status" 0 "$?"

  # pitwall ends on Ctrl-C, as without a browser (exit status 130), within 10 s.
  local deadline=$((SECONDS + 10))
  while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.05; done
  if kill -0 "$pid" 2>/dev/null; then
    fail "pitwall still runs 10 s after SIGINT"
  else
    wait "$pid"
    check "pitwall exit status after Ctrl-C" 130 "$?"
    pid=""
  fi
  [ -s "$ART/view-$name.png" ] && echo "ok: screenshot $ART/view-$name.png" ||
    fail "no screenshot at $ART/view-$name.png"
  if [ "$FAILURES" -ne 0 ]; then
    echo "pitwall's stderr:"
    sed 's/^/  | /' "$TMP/err" | tail -40
  fi
}

in_browser chromium --chromium "$CHROMIUM"
in_browser firefox --firefox "$FIREFOX"
finish
