#!/usr/bin/env bash
# The join code as a QR (docs/view.md "Pairing"): a run with --view on 0.0.0.0 prints the join
# code and the controller page's address on this machine's LAN address; the race view shows that
# address as a QR code, which Debian's zbarimg decodes from a screenshot in headless Chromium
# (tests/view/qr_check.mjs); the address opens the controller page from a non-loopback address,
# paired. Screenshots in ./view_test_artifacts/qr*.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"
command -v zbarimg >/dev/null || { echo "FAIL: zbarimg is missing; install zbar-tools (./dev test does)"; exit 1; }

install_checks view_qr_check qr_check.mjs
artifacts 'qr*.png'

"$PITWALL" run "$SRC/tests/view/drive_race.lua" --view 0.0.0.0:0 --humans 2 --cars 2 \
  --duration 300 > "$TMP/out" 2> "$TMP/err" &
pid=$!
if await_code "$TMP/err"; then
  lan=$(grep -oE "phones open http://[^ ]+/drive\?code=$code" "$TMP/err" | head -1 | sed 's/^phones open //')
  case "$lan" in
    http://127.*|http://localhost*|http://0.0.0.0*|"") fail "the terminal's address for phones is no LAN address: [$lan]" ;;
    *) echo "ok: the terminal prints the LAN address for phones ($lan)" ;;
  esac
  timeout -k 5 120 node "$CHECK/qr_check.mjs" "http://127.0.0.1:$port/" "$code" "$ART/qr.png" \
    --timeout 30 --chromium "$CHROMIUM"
  check "QR check exit status" 0 "$?"
else
  fail "pitwall --view 0.0.0.0:0 printed no join code within 20 s"
fi
kill -INT "$pid"
await_end "pitwall after Ctrl-C" 10 130
show_if_failed "pitwall's stderr" "$TMP/err"
finish
