#!/usr/bin/env bash
# The controller page in a real browser (docs/view.md "The controller page (/drive)"): a run with
# --view on a free port and --humans 2 on the simulator in real time, whose script
# (tests/view/drive_race.lua) drives cars 1 and 2 with human drivers; two headless Chromium pages
# on /drive (tests/view/drive_check.mjs, puppeteer-core pinned by tests/view/package-lock.json):
# seats taken and refused, the throttle moves car 1 and only car 1, letting go and closing the page
# stop it; then the party (examples/party.lua) to its end, one phone upright (390×844) and one on
# its side (844×390): the lights and the countdown, GO, the place and lap, "Finished — P<n>" and
# the result with no throttle, every state fitting the screen without scrolling. Screenshots of
# each state in ./view_test_artifacts/drive-*.png.
source "$(dirname "$0")/lib.sh"
source "$(dirname "$0")/browser_lib.sh"

install_checks drive_browser_check drive_check.mjs
artifacts 'drive-*.png'

start_drive_race
await_view "$TMP/err" || finish

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
await_end "pitwall after Ctrl-C" 10 130
show_if_failed "pitwall's stderr" "$TMP/err"

# Pairing (docs/view.md "Pairing"): on 0.0.0.0 a seat needs the join code the run prints; the
# pages are opened by 127.0.0.1 (a name the view serves) with the code the terminal printed.
"$PITWALL" run "$SRC/tests/view/drive_race.lua" --view 0.0.0.0:0 --humans 2 --cars 2 \
  --duration 300 > "$TMP/pair.out" 2> "$TMP/pair.err" &
pid=$!
if await_code "$TMP/pair.err"; then
  contains "the drive line carries the code" "/drive?code=$code (cars 1..2" "$(cat "$TMP/pair.err")"
  timeout -k 5 240 node "$CHECK/drive_check.mjs" "http://127.0.0.1:$port/" --code "$code" \
    --timeout 30 --chromium "$CHROMIUM" --artifacts "$ART"
  check "pairing check exit status" 0 "$?"
else
  fail "pitwall --view 0.0.0.0:0 printed no join code within 20 s"
fi
kill -INT "$pid"
await_end "pitwall on 0.0.0.0 after Ctrl-C" 10 130
show_if_failed "the pairing run's stderr" "$TMP/pair.err"

# Done when: two people with phones and two AI drivers run a race (examples/party.lua, one lap)
# to its end, with the race view showing it.
LAPS=1 WAIT=120 SHOW=10 "$PITWALL" run "$SRC/examples/party.lua" --view 127.0.0.1:0 --humans 2 --cars 4 \
  --duration 300 > "$TMP/party.out" 2> "$TMP/party.err" &
pid=$!
if await_view "$TMP/party.err" party; then
  timeout -k 5 280 node "$CHECK/drive_check.mjs" "$url" --party --timeout 120 --chromium "$CHROMIUM" \
    --artifacts "$ART"
  check "party check exit status" 0 "$?"
  await_end "the party" 40 0  # the script ends the run itself once the results were shown (SHOW)
  contains "the party names a winner" "Winner: " "$(cat "$TMP/party.out")"
  contains "the party waited for both players" "seat 2: Ben" "$(cat "$TMP/party.out")"
  show_if_failed "the party's stderr" "$TMP/party.err"
fi
finish
