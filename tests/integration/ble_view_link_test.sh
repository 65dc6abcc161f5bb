# A car's link health where people see it (issue 36; docs/view.md "Leaderboard", docs/cli.md
# "Record format"): a race over the fake BlueZ with --view and --record, whose car 2 reboots for
# 5 s. In headless Chromium (tests/view/link_check.mjs) the leaderboard's Link cell of car 2 says
# "down" while it is away, then "1 drop" with the reason in its title. The record keeps link lines,
# and `pitwall replay` counts the drop from them, with its reason. Screenshot in
# ./view_test_artifacts/link.png.
source "$(dirname "$0")/ble_lib.sh"
source "$(dirname "$0")/browser_lib.sh"
trap 'cleanup_ble; cleanup' EXIT
install_checks view_link_check link_check.mjs
artifacts 'link*.png'
start_bus
start_fake --adapters 1 --cars 2 --fault "reboot:E0:00:00:00:00:02@12+5"

LAPS=50 "$PITWALL" run "$SRC/examples/grand_prix.lua" --ble --scan-timeout 1 --view 127.0.0.1:0 \
  --record "$TMP/race.jsonl" >"$TMP/out" 2>"$TMP/err" &
pid=$!
if await_view "$TMP/err" "real cars"; then
  timeout -k 5 150 node "$CHECK/link_check.mjs" "$url" 2 "$ART/link.png" --timeout 60 \
    --chromium "$CHROMIUM"
  check "link check exit status" 0 "$?"
fi
kill -INT "$pid"
await_end "pitwall after Ctrl-C" 20 130
show_if_failed "pitwall's stderr" "$TMP/err"
stop_fake

# The record: car 2's link went down once, with the reason, and came back
lines=$(python3 - "$TMP/race.jsonl" <<'PY'
import json, sys
for line in open(sys.argv[1]):
    r = json.loads(line)
    if "link" in r:
        l = r["link"]
        print(r["car"], "up" if l["up"] else "down", l["connects"], l["drops"], l["reason"] or "")
PY
)
echo "$lines"
check "the record: car 2's link went down once" 1 "$(echo "$lines" | grep -c '^2 down ')"
contains "the record: and came back" "2 up 2 1" "$lines"
# A replay plays the link lines: the drop counted, its reason kept
out=$("$PITWALL" replay "$TMP/race.jsonl" --json 2>"$TMP/replay.err")
check "replay --json: exit status" 0 "$?"
car2=$(echo "$out" | python3 -c 'import json,sys
for l in sys.stdin:
    r = json.loads(l)
    if r["car"] == 2: print(r["drops"], "reason" if r["lastDrop"] else "none")')
check "replay: car 2's drop, from the record's link lines" "1 reason" "$car2"
finish
