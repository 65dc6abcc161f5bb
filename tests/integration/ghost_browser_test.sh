#!/usr/bin/env bash
# The ghost in the race view, in headless Chromium (docs/view.md "Ghosts and deltas",
# tests/view/ghost_check.mjs): a record's lap driven again by sim.addGhost beside car 1, drawn
# translucent and moving, car 1's live delta to it on the leaderboard. Screenshot
# ./view_test_artifacts/ghost.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"

install_checks ghost_browser_check ghost_check.mjs
artifacts 'ghost*.png'

cd "$TMP" || exit 2
"$PITWALL" run "$SRC/tests/integration/compare_drive.lua" --fast --record even.jsonl -q ||
  fail "the lap's record"
"$PITWALL" run "$SRC/tests/view/ghost_race.lua" --view 127.0.0.1:0 > "$TMP/out" 2> "$TMP/err" &
pid=$!
if await_view "$TMP/err"; then
  timeout -k 5 120 node "$CHECK/ghost_check.mjs" "$url" "$ART/ghost.png" --timeout 40 \
    --chromium "$CHROMIUM" > "$TMP/check" 2>&1
  status=$?
  cat "$TMP/check"
  check "the ghost check: exit status" 0 "$status"
  grep -q '^FAIL' "$TMP/check" && fail "a check in the browser failed"
fi
show_if_failed "pitwall's stderr" "$TMP/err"
exit $((FAILURES > 0))
