#!/usr/bin/env bash
# Runs inside the QEMU guest of tests/qemu/ble_e2e.sh, chrooted into the host's tree (read-only;
# /tmp, /run, /var/lib/bluetooth are tmpfs): a private system bus, `btvirt -l2`, the real
# bluetoothd, `pitwall emulate-car` on hci0, then the central on hci1. Exit status: 0 passed,
# 1 failed (with the last lines of each log).
#
#   guest.sh PITWALL SOURCE_DIR CENTRALS BLUETOOTHD
#
# CENTRALS: one or more of bleak, pitwall, tools, both (= tools,pitwall), script:FILE, separated
# by commas, run in that order against the same car (ble_e2e.sh says what each does).
set -uo pipefail
PITWALL=$1
SRC=$2
CENTRALS=$3
BLUETOOTHD=$4
source "$SRC/tests/qemu/guest_lib.sh"  # LOGS, say, fail, until_ok
FAIL_STATUS=75  # until pitwall's code takes part (below)
bluez_get() {  # bluez_get PATH INTERFACE PROPERTY → the value as dbus-send prints it
  dbus-send --system --print-reply --dest=org.bluez "$1" org.freedesktop.DBus.Properties.Get \
    "string:$2" "string:$3" | sed -n '2,$p'
}
powered() { bluez_get "/org/bluez/$1" org.bluez.Adapter1 Powered | grep -q 'boolean true'; }

# ---- the Bluetooth stack ----
DBUS_SYSTEM_BUS_ADDRESS=$(dbus-daemon --config-file="$SRC/tests/support/bus.conf" --fork \
  --print-address=1) || fail "dbus-daemon did not start"
export DBUS_SYSTEM_BUS_ADDRESS
say "private system bus at $DBUS_SYSTEM_BUS_ADDRESS"

btvirt -l2 >"$LOGS/btvirt.log" 2>&1 &
until_ok 10 test -e /sys/class/bluetooth/hci1 || fail "btvirt -l2 made no hci0/hci1"
say "btvirt: two emulated LE controllers"

debug=()
[ "${PITWALL_QEMU_LOG:-info}" = debug ] && debug=(-d)
# No plugins: the GATT server, the GATT client and advertising are bluetoothd's core; the
# plugins (audio, input, policy, …) only add start-up time under TCG.
start_bluetoothd() {
  "$BLUETOOTHD" -n -E -P '*' "${debug[@]}" >>"$LOGS/bluetoothd.log" 2>&1 &
  BLUETOOTHD_PID=$!
  until_ok 10 bluez_get /org/bluez/hci1 org.bluez.Adapter1 Address
}
start_bluetoothd || fail "bluetoothd has no hci1"
# Setting Powered while bluetoothd still sets the adapter up answers org.bluez.Error.Busy: retry.
set_powered() {  # set_powered hciN true|false
  dbus-send --system --print-reply --dest=org.bluez "/org/bluez/$1" \
    org.freedesktop.DBus.Properties.Set string:org.bluez.Adapter1 string:Powered \
    "variant:boolean:$2"
}
power_on() { set_powered "$1" true && until_ok 1 powered "$1"; }
for hci in hci0 hci1; do
  until_ok 10 power_on "$hci" || fail "$hci did not power on"
done
ADDR0=$(bluez_get /org/bluez/hci0 org.bluez.Adapter1 Address | sed -n 's/.*string "\(.*\)"/\1/p')
ADDR1=$(bluez_get /org/bluez/hci1 org.bluez.Adapter1 Address | sed -n 's/.*string "\(.*\)"/\1/p')
say "bluetoothd $("$BLUETOOTHD" -v): hci0 $ADDR0 and hci1 $ADDR1 powered"

# ---- the peripheral: pitwall emulate-car on hci0, its output streamed ----
# Meanwhile, an adapter BlueZ does not have must give one sentence and status 2.
# From here pitwall's code takes part: a failure above (the bus, btvirt, bluetoothd, the
# adapters powered) is the emulation's, exit 75, which ble_e2e.sh boots once more; one below
# fails the test (tests/qemu/README.md "A failed boot").
FAIL_STATUS=1
"$PITWALL" emulate-car --adapter hci9 >"$LOGS/hci9.out" 2>&1 &
HCI9_PID=$!
# every code and the exact speed: the centrals check speeds and count laps from positions
"$PITWALL" --log-level "${PITWALL_QEMU_LOG:-info}" emulate-car --sensor ideal --adapter hci0 --name pitwall \
  > >(sed -u 's/^/[car] /') 2>&1 &
CAR_PID=$!
say "pitwall emulate-car started (pid $CAR_PID)"

# ---- the central on hci1 ----
central_pitwall() {
  local status=0
  "$PITWALL" run "$SRC/tests/qemu/laps_ble.lua" --ble --adapter hci1 --car "$ADDR0" --duration 30 \
    2>&1 | tee "$LOGS/central.out" | sed -u 's/^/[central] /'
  status=${PIPESTATUS[0]}
  [ "$status" -eq 0 ] || return "$status"
  # --duration ending the run is status 0 too: only the script's last line says it drove.
  grep -q "laps driven over BLE" "$LOGS/central.out" || {
    say "the script never reported its laps"
    return 1
  }
}

# pitwall's scanner, then a py-drivesdk-like client on bleak (tests/qemu/central_drivesdk.py).
# links: a race's link through the real bluetoothd's faults (issue 36, docs/bluetooth.md "What
# survives what"): the car driven by tests/qemu/links_ble.lua on hci1; the central's controller
# powered off for 3 s, then bluetoothd restarted (the emulated car registers again when it is
# back). After each the car must drive again within LINKS_BOUND s (measured: the "back" lines).
LINKS_BOUND=30
central_links() {
  local out="$LOGS/links.out" pid status
  : >"$out"
  "$PITWALL" run "$SRC/tests/qemu/links_ble.lua" --ble --adapter hci1 --car "$ADDR0" \
    --duration 150 > >(tee -a "$out" | sed -u 's/^/[links] /') 2>&1 &
  pid=$!
  until_ok 40 grep -q '^driving' "$out" || { say "the car never drove"; kill -INT "$pid"; return 1; }
  say "links: the car drives; hci1 (the central's controller) powered off for 3 s"
  set_powered hci1 false >/dev/null || { say "cannot power hci1 off"; kill -INT "$pid"; return 1; }
  sleep 3  # the fault's length: the controller stays off this long
  power_on hci1 >/dev/null || { say "hci1 did not power on again"; kill -INT "$pid"; return 1; }
  until_ok "$LINKS_BOUND" grep -q '^back 1 ' "$out" ||
    { say "the car did not drive again within $LINKS_BOUND s of hci1 powered on"; kill -INT "$pid"; return 1; }
  say "links: power cycle: $(grep -m1 '^back 1 ' "$out")"
  say "links: bluetoothd restarted"
  kill -TERM "$BLUETOOTHD_PID"
  wait "$BLUETOOTHD_PID"
  start_bluetoothd || { say "bluetoothd did not come back"; kill -INT "$pid"; return 1; }
  for hci in hci0 hci1; do until_ok 10 power_on "$hci" || { say "$hci did not power on"; kill -INT "$pid"; return 1; }; done
  until_ok "$LINKS_BOUND" grep -q '^back 2 ' "$out" ||
    { say "the car did not drive again within $LINKS_BOUND s of bluetoothd's restart"; kill -INT "$pid"; return 1; }
  say "links: bluetoothd restart: $(grep -m1 '^back 2 ' "$out")"
  kill -INT "$pid"
  wait "$pid"
  status=$?
  [ "$status" -eq 130 ] || { say "pitwall run ended with status $status after Ctrl-C, not 130"; return 1; }
}

central_bleak() {
  # `pitwall scan` through the real BlueZ: the emulated car's Anki-shaped name (state byte,
  # version, filler, user name) reads as a clean name with its state and version.
  : >"$LOGS/bleak.out"
  "$PITWALL" scan --adapter hci1 --timeout 2 --json >"$LOGS/scan.json" 2>"$LOGS/scan.log" || {
    say "pitwall scan failed: $(cat "$LOGS/scan.log")"
    return 1
  }
  /usr/bin/python3 - "$LOGS/scan.json" "$ADDR0" "$LOGS/bleak.out" <<'EOF' || return 1
import json, sys
cars = [json.loads(line) for line in open(sys.argv[1]) if line.strip()]
car = next((c for c in cars if c["address"] == sys.argv[2]), None)
want = {"name": "pitwall", "battery": "full", "firmware": 0x2B70, "modelId": 8}
got = {k: car.get(k) for k in want} if car else None
print(f"[scan] {got}" if got == want else f"[scan] {cars}, want {want}")
open(sys.argv[3], "a").write("[scan] []\n" if car is None else "")  # not seen: for unseen()
sys.exit(0 if got == want else 1)
EOF
  /usr/bin/python3 "$SRC/tests/qemu/central_drivesdk.py" --adapter hci1 --address "$ADDR0" 2>&1 |
    tee -a "$LOGS/bleak.out" | sed -u 's/^/[bleak] /'
  return "${PIPESTATUS[0]}"
}

# After a central failed: do the emulated radios hear each other? hci0 has an advertisement
# registered (btmgmt advinfo) and LE discovery on hci1 with BlueZ's own btmgmt — no pitwall code —
# does not find it in 10 s: the failure is shown to be the emulation's (btvirt under TCG on a
# loaded machine), not pitwall's (tests/qemu/README.md "A failed boot").
radios_deaf() {
  btmgmt --index 0 advinfo >"$LOGS/radios.log" 2>&1
  grep -Eq "Instances list with [1-9]" "$LOGS/radios.log" || return 1
  timeout 10 stdbuf -oL btmgmt --index 1 find -l >>"$LOGS/radios.log" 2>&1
  btmgmt --index 1 stop-find -l >>"$LOGS/radios.log" 2>&1
  ! grep -qi "dev_found: $ADDR0 " "$LOGS/radios.log"
}

# Did a failed central never see the car at all (no advertisement reached it)?
unseen() {
  case "$1" in
    bleak) grep -q "no car py-drivesdk takes advertised" "$LOGS/bleak.out" 2>/dev/null ||
      grep -q '^\[scan\] \[\]' "$LOGS/bleak.out" 2>/dev/null ;;
    pitwall) grep -q "no Anki car found" "$LOGS/central.out" 2>/dev/null ;;
    links) grep -q "no Anki car found" "$LOGS/links.out" 2>/dev/null ;;
    *) return 1 ;;
  esac
}

central_status=0 deaf=0 unseen_failures=0
IFS=, read -r -a centrals <<<"${CENTRALS//both/tools,pitwall}"
for central in "${centrals[@]}"; do
  status=0
  case "$central" in
    tools)
      source "$SRC/tests/qemu/central_tools.sh"
      central_tools "$ADDR0" || status=$?
      ;;
    pitwall) central_pitwall || status=$? ;;
    bleak) central_bleak || status=$? ;;
    links) central_links || status=$? ;;
    script:*)  # a developer's own check, sourced here with this file's variables
      source "${central#script:}" || status=$?
      ;;
  esac
  if [ "$status" -eq 0 ]; then
    say "central '$central' passed"
  elif unseen "$central"; then
    # the car never seen: the emulation's when btmgmt shows the radios deaf (now, or earlier in
    # this boot: the deafness comes and goes)
    radios_deaf && deaf=1
    say "central '$central' FAILED with status $status: the car was never seen$([ "$deaf" = 1 ] &&
      echo ", and BlueZ's own btmgmt on hci1 did not hear hci0 advertising either (radios.log, below)")"
    unseen_failures=$((unseen_failures + 1))
  else
    say "central '$central' FAILED with status $status"
    central_status=$status
  fi
done

wait "$HCI9_PID"
status=$?
err=$(cat "$LOGS/hci9.out")
[ "$status" -eq 2 ] && [[ "$err" == *"no adapter hci9"* ]] ||
  fail "emulate-car --adapter hci9: expected status 2 and 'no adapter hci9', got $status: $err"
say "emulate-car --adapter hci9: status 2, \"$err\""

# ---- shutdown: SIGTERM must end emulate-car cleanly (status 0) ----
if kill -0 "$CAR_PID" 2>/dev/null; then
  kill -TERM "$CAR_PID"
  wait "$CAR_PID"
  car_status=$?
else
  wait "$CAR_PID"
  car_status=$?
  say "pitwall emulate-car had already exited"
fi
[ "$central_status" -eq 0 ] || fail "a central of '$CENTRALS' failed (status $central_status)"
if [ "$unseen_failures" -gt 0 ]; then
  # only failures to see the car at all: the emulation's when btmgmt showed the radios deaf
  [ "$deaf" = 1 ] && FAIL_STATUS=75
  fail "$unseen_failures central(s) never saw the car$([ "$deaf" = 1 ] &&
    echo ", while BlueZ's own btmgmt showed hci1 deaf to hci0: the emulation's failure" ||
    echo " though BlueZ's own btmgmt heard it")"
fi
[ "$car_status" -eq 0 ] || fail "pitwall emulate-car exited with status $car_status after SIGTERM"
say "passed: centrals '$CENTRALS', emulate-car stopped cleanly"
exit 0
