#!/usr/bin/env bash
# The code editor's bundle (issue 39's editor; engine/view/page/editor/pitwall_editor.js, built from
# the pinned CodeMirror packages by esbuild) served by a run's race view and used in headless
# Chromium (tests/view/editor_check.mjs): Lua highlighting, completions by prefix, an error marked
# at its line, changes reported. Screenshot in ./view_test_artifacts/editor.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"

install_checks view_editor_check editor_check.mjs
artifacts 'editor*.png'

start_drive_race
if await_view "$TMP/err" editor; then
  timeout -k 5 120 node "$CHECK/editor_check.mjs" "$url" "$ART/editor.png" --timeout 30 \
    --chromium "$CHROMIUM"
  check "editor check exit status" 0 "$?"
  [ -s "$ART/editor.png" ] && echo "ok: screenshot $ART/editor.png" || fail "no screenshot at $ART/editor.png"
fi
kill -INT "$pid"
await_end "pitwall after Ctrl-C" 10 130
show_if_failed "pitwall's stderr" "$TMP/err"
finish
