#!/usr/bin/env bash
# The race view in a real browser (docs/view.md): a grand prix with --view on a free port, the page
# loaded in headless Chromium and in Firefox ESR (tests/view/browser_check.mjs, puppeteer-core pinned by
# tests/view/package-lock.json): track, 4 moving cars, leaderboard, charts; from the page's first
# moments to 8 s of racing (--race-start) every car drawn and listed through the scan, the grid
# and the lights, standing cars at 0 mm/s, the gaps in order on every update; then Ctrl-C to the
# engine and the open page says "engine gone". Screenshots in ./view_test_artifacts/.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"
need_firefox

install_checks view_browser_check browser_check.mjs
artifacts 'view-*.png'

# in_browser NAME BROWSER-OPTION PATH: a long race (it must not end by itself before the check is
# done), real time, any free port; the page checked in that browser, then SIGINT to pitwall and
# the open page says "engine gone"; an engine started again on the same address, and the page
# says "live" by itself with the cars back. Screenshots $ART/view-NAME.png and view-NAME-gone.png.
in_browser() {
  local name=$1 option=$2 path=$3
  # Emptied here, not by the redirection below: that happens in the background child, after
  # await_view may already have read the previous run's address from the old file.
  : > "$TMP/out"
  : > "$TMP/err"
  LAPS=50 "$PITWALL" run "$SRC/examples/grand_prix.lua" --view 127.0.0.1:0 \
    > "$TMP/out" 2> "$TMP/err" &
  pid=$!
  await_view "$TMP/err" "$name" || finish
  local addr=${url#http://}
  addr=${addr%/}

  # /api/state answers the whole state as JSON (the page itself uses /ws).
  state=$(timeout 20 node -e '
    fetch(process.argv[1] + "api/state").then((r) => r.json()).then((s) => {
      console.log(`${s.type} track=${s.track ? s.track.name : null} cars=${s.cars.length}`);
    }).catch((e) => { console.log(`error ${e.message}`); process.exit(1); });' "$url")
  check "/api/state is the whole state" "state track=oval cars=4" "$state"

  timeout -k 5 180 node "$CHECK/browser_check.mjs" "$url" "$ART/view-$name.png" \
    --expect-cars 4 --race-start --kill "$pid" --timeout 40 "$option" "$path" \
    --restart "$(printf '%q ' "$PITWALL" run "$SRC/examples/grand_prix.lua" --view "$addr")"
  check "$name: browser check exit status" 0 "$?"

  # pitwall ends on Ctrl-C, as without a browser (exit status 130), within 10 s.
  await_end "pitwall after Ctrl-C" 10 130
  [ -s "$ART/view-$name.png" ] && echo "ok: screenshot $ART/view-$name.png" ||
    fail "no screenshot at $ART/view-$name.png"
  show_if_failed "pitwall's stderr" "$TMP/err"
}

in_browser chromium --chromium "$CHROMIUM"
in_browser firefox --firefox "$FIREFOX"
finish
