# pitwall scan as a user runs it, against the fake BlueZ on a private bus: the table, JSON lines,
# adapters, and one clear sentence with exit status 2 for each way BlueZ cannot be used.
source "$(dirname "$0")/ble_lib.sh"

# No system bus at all
err=$(DBUS_SYSTEM_BUS_ADDRESS=unix:path=$TMP/nobus $PITWALL scan --timeout 0.2 2>&1 >/dev/null); rc=$?
check "no bus: exit status" 2 "$rc"
contains "no bus: says so" "cannot reach the system D-Bus" "$err"

start_bus

# A bus without BlueZ
err=$($PITWALL scan --timeout 0.2 2>&1 >/dev/null); rc=$?
check "no BlueZ: exit status" 2 "$rc"
contains "no BlueZ: says so" "BlueZ is not running" "$err"

# BlueZ without an adapter
start_fake --adapters 0 --cars 0
err=$($PITWALL scan --timeout 0.2 2>&1 >/dev/null); rc=$?
check "no adapter: exit status" 2 "$rc"
contains "no adapter: says so" "no Bluetooth adapter found" "$err"
stop_fake

# Three cars on two adapters
start_fake --adapters 2 --cars 3 --name "Red Devil" --name Ghost --name Blue
out=$($PITWALL scan --timeout 1); rc=$?
check "table: exit status" 0 "$rc"
check "table: header" "ADDRESS NAME MODEL FIRMWARE BATTERY RSSI ADAPTER" \
  "$(echo "$out" | sed -n 1p | tr -s ' ')"
check "table: one row per car" 4 "$(echo "$out" | wc -l)"
row=$(echo "$out" | grep "E0:00:00:00:00:01" | tr -s ' ')
contains "table: the user name, with its space" "Red Devil" "$row"
contains "table: model" "Groundshock" "$row"
contains "table: firmware" "0x2b70" "$row"
contains "table: signal strength" " dBm" "$row"
contains "table: the adapter" "hci0" "$(echo "$out" | grep E0:00:00:00:00:03)"
contains "table: the other adapter" "hci1" "$(echo "$out" | grep E0:00:00:00:00:02)"

json=$($PITWALL scan --timeout 1 --json); rc=$?
check "json: exit status" 0 "$rc"
check "json: one line per car" 3 "$(echo "$json" | wc -l)"
parsed=$(echo "$json" | /usr/bin/python3 -c '
import json, sys
cars = sorted((json.loads(l) for l in sys.stdin), key=lambda c: c["address"])
for c in cars:
    print(c["address"], c["name"], c["model"], c["modelId"], c["firmware"], c["battery"],
          type(c["rssi"]).__name__, c["adapter"])
')
check "json: fields" "E0:00:00:00:00:01 Red Devil Groundshock 8 11120 ok int hci0
E0:00:00:00:00:02 Ghost Skull 9 11120 ok int hci1
E0:00:00:00:00:03 Blue Thermo 10 11120 ok int hci0" "$parsed"

out=$($PITWALL scan --timeout 1 --adapter hci1 --json)
check "--adapter: only that adapter's cars" "E0:00:00:00:00:02" \
  "$(echo "$out" | /usr/bin/python3 -c 'import json,sys; print(" ".join(json.loads(l)["address"] for l in sys.stdin))')"

# An adapter switched off (bluetoothctl power off)
dbus-send --system --print-reply --dest=org.bluez /org/bluez/hci1 \
  org.freedesktop.DBus.Properties.Set string:org.bluez.Adapter1 string:Powered \
  variant:boolean:false >/dev/null
err=$($PITWALL scan --timeout 0.3 --adapter hci1 2>&1 >/dev/null); rc=$?
check "powered off: exit status" 2 "$rc"
contains "powered off: names it and says what to do" \
  "Bluetooth adapter hci1 is powered off: switch it on with \`bluetoothctl power on\`" "$err"

err=$($PITWALL scan --timeout 1 --adapter hci7 2>&1 >/dev/null); rc=$?
check "unknown adapter: exit status" 2 "$rc"
contains "unknown adapter: names what there is" "there is no Bluetooth adapter hci7 (found: hci0, hci1)" "$err"
stop_fake

# Nothing in range: an empty result is not an error
start_fake --adapters 1 --cars 0
out=$($PITWALL scan --timeout 0.3); rc=$?
check "nothing found: exit status" 0 "$rc"
contains "nothing found: says so" "no Anki cars found" "$out"
stop_fake

# A bus that refuses us BlueZ (a policy without the hole bluetooth.conf punches for users)
kill "$BUS_PID"
sed 's|<allow send_destination="\*" eavesdrop="true"/>|<deny send_destination="org.bluez"/>|' \
  "$SRC/tests/support/bus.conf" >"$TMP/deny.conf"
out=$(dbus-daemon --config-file="$TMP/deny.conf" --fork --nosyslog --print-address=1 --print-pid=1)
export DBUS_SYSTEM_BUS_ADDRESS=$(echo "$out" | sed -n 1p)
BUS_PID=$(echo "$out" | sed -n 2p)
start_fake --adapters 1 --cars 1
err=$($PITWALL scan --timeout 0.3 2>&1 >/dev/null); rc=$?
check "no permission: exit status" 2 "$rc"
contains "no permission: says so" "no permission to use BlueZ" "$err"

finish
