#!/usr/bin/env bash
# The controller page in a real browser (docs/view.md "The controller page (/drive)"): a run with
# --view on a free port and --humans 2 on the simulator in real time, whose script
# (tests/view/drive_race.lua) drives cars 1 and 2 with human drivers; two headless Chromium pages
# on /drive (tests/view/drive_check.mjs, puppeteer-core pinned by tests/view/package-lock.json):
# seats taken and refused, the throttle moves car 1 and only car 1, letting go and closing the page
# stop it. Screenshots in ./view_test_artifacts/drive-page*.png.
source "$(dirname "$0")/lib.sh"

pid=""
cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT

# Real parts: no browser or no node is a failure, not a skip (./dev test installs them).
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
command -v node >/dev/null || { echo "FAIL: node is missing; install nodejs (./dev test does)"; exit 1; }
command -v npm >/dev/null || { echo "FAIL: npm is missing; install npm (./dev test does)"; exit 1; }
[ -x "$CHROMIUM" ] || { echo "FAIL: no Chromium at $CHROMIUM; install chromium (./dev test does) or set CHROMIUM"; exit 1; }

# puppeteer-core, installed once in the build tree (again when the lockfile changes); a folder
# of its own, so that this test and view_browser_test may run at once.
CHECK="$PWD/drive_browser_check"
mkdir -p "$CHECK"
if ! cmp -s "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock" ||
   [ ! -d "$CHECK/node_modules/puppeteer-core" ]; then
  cp "$SRC/tests/view/package.json" "$SRC/tests/view/package-lock.json" "$CHECK/"
  if ! (cd "$CHECK" && timeout 300 npm ci --no-audit --no-fund --prefer-offline --loglevel=error); then
    echo "FAIL: npm ci of tests/view (puppeteer-core) in $CHECK"
    exit 1
  fi
  cp "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock"
fi
cp "$SRC/tests/view/drive_check.mjs" "$CHECK/"  # beside its node_modules

ART="$PWD/view_test_artifacts"
mkdir -p "$ART"
rm -f "$ART"/drive-page*.png

"$PITWALL" run "$SRC/tests/view/drive_race.lua" --view 127.0.0.1:0 --humans 2 --cars 2 \
  --duration 300 > "$TMP/out" 2> "$TMP/err" &
pid=$!
if ! wait_for "$TMP/err" '^view: http://127\.0\.0\.1:[0-9]+/' 20; then
  fail "pitwall printed no 'view: http://127.0.0.1:PORT/' line within 20 s; its stderr:"
  sed 's/^/  | /' "$TMP/err"
  finish
fi
url=$(grep -oE '^view: http://127\.0\.0\.1:[0-9]+/' "$TMP/err" | head -1 | sed 's/^view: //')
echo "ok: view at $url"

# GET /drive is the controller page
page=$(timeout 20 node -e '
  fetch(process.argv[1] + "drive").then(async (r) => {
    const t = await r.text();
    console.log(`${r.status} ${/<title>pitwall · drive<\/title>/.test(t)}`);
  }).catch((e) => { console.log(`error ${e.message}`); process.exit(1); });' "$url")
check "GET /drive serves the controller page" "200 true" "$page"

timeout -k 5 240 node "$CHECK/drive_check.mjs" "$url" --timeout 30 --chromium "$CHROMIUM" \
  --artifacts "$ART"
check "drive check exit status" 0 "$?"

# The engine said who took and left the seats, and ends on Ctrl-C as always.
contains "the log names the seat taken by a phone" "seat 1 taken by a phone (Anna)" "$(cat "$TMP/err")"
contains "the log says the phone went" "the phone disconnected" "$(cat "$TMP/err")"
kill -INT "$pid"
deadline=$((SECONDS + 10))
while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.05; done
if kill -0 "$pid" 2>/dev/null; then
  fail "pitwall still runs 10 s after SIGINT"
else
  wait "$pid"
  check "pitwall exit status after Ctrl-C" 130 "$?"
  pid=""
fi
if [ "$FAILURES" -ne 0 ]; then
  echo "pitwall's stderr:"
  sed 's/^/  | /' "$TMP/err" | tail -40
fi

# Done when: two people with phones and two AI drivers run a race (examples/party.lua, one lap)
# to its end, with the race view showing it.
LAPS=1 WAIT=120 SHOW=10 "$PITWALL" run "$SRC/examples/party.lua" --view 127.0.0.1:0 --humans 2 --cars 4 \
  --duration 300 > "$TMP/party.out" 2> "$TMP/party.err" &
pid=$!
if wait_for "$TMP/party.err" '^view: http://127\.0\.0\.1:[0-9]+/' 20; then
  url=$(grep -oE '^view: http://127\.0\.0\.1:[0-9]+/' "$TMP/party.err" | head -1 | sed 's/^view: //')
  timeout -k 5 280 node "$CHECK/drive_check.mjs" "$url" --party --timeout 120 --chromium "$CHROMIUM" \
    --artifacts "$ART"
  check "party check exit status" 0 "$?"
  deadline=$((SECONDS + 40))  # the script ends the run itself once the results were shown (SHOW)
  while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.1; done
  if kill -0 "$pid" 2>/dev/null; then
    fail "the party did not end 40 s after the check"
  else
    wait "$pid"
    check "party exit status" 0 "$?"
    pid=""
  fi
  contains "the party names a winner" "Winner: " "$(cat "$TMP/party.out")"
  contains "the party waited for both players" "seat 2: Ben" "$(cat "$TMP/party.out")"
else
  fail "the party printed no 'view: http://127.0.0.1:PORT/' line within 20 s"
fi
if [ "$FAILURES" -ne 0 ]; then
  echo "the party's stderr:"
  sed 's/^/  | /' "$TMP/party.err" | tail -40
fi
finish
