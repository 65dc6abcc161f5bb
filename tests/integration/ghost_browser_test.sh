#!/usr/bin/env bash
# The ghost in the race view, in headless Chromium (docs/view.md "Ghosts and deltas",
# tests/view/ghost_check.mjs): a record's lap driven again by sim.addGhost beside car 1, drawn
# translucent and moving, car 1's live delta to it on the leaderboard; then, with no simulated
# ghost, the view's own ghost of the track's personal best from the standings
# (tests/view/view_ghost_check.mjs). Screenshots ./view_test_artifacts/ghost*.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"

install_checks ghost_browser_check ghost_check.mjs view_ghost_check.mjs
artifacts 'ghost*.png'

cd "$TMP" || exit 2
"$PITWALL" run "$SRC/tests/integration/compare_drive.lua" --fast --record even.jsonl -q ||
  fail "the lap's record"
# browse NAME CHECK SHOT RUN-OPTIONS…: a run with the view, and CHECK's browser checks of it
browse() {
  local name=$1 checker=$2 shot=$3
  shift 3
  "$PITWALL" run "$@" --view 127.0.0.1:0 > "$TMP/out" 2> "$TMP/err" &
  local pid=$!
  if await_view "$TMP/err"; then
    timeout -k 5 120 node "$CHECK/$checker" "$url" "$ART/$shot" --timeout 40 \
      --chromium "$CHROMIUM" > "$TMP/check" 2>&1
    local status=$?
    cat "$TMP/check"
    check "$name: exit status" 0 "$status"
    grep -q '^FAIL' "$TMP/check" && fail "$name: a check in the browser failed"
  fi
  show_if_failed "pitwall's stderr" "$TMP/err"
  kill "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
}

browse "the ghost check" ghost_check.mjs ghost.png "$SRC/tests/view/ghost_race.lua"

# The view's own ghost: a race kept in the standings leaves the track's personal best (car 1 at
# the cruiser's pace); car 1 alone at 600 mm/s races against it
export PITWALL_DB="$TMP/st.db"
LAPS=2 "$PITWALL" run "$SRC/examples/time_trial.lua" --fast --cars 1 -q > /dev/null 2>&1 ||
  fail "the race that keeps a personal best"
browse "the view's ghost check" view_ghost_check.mjs ghost-view.png "$SRC/tests/view/pb_drive.lua" \
  --cars 1
exit $((FAILURES > 0))
