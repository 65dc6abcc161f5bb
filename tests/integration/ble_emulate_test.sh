# pitwall emulate-car's ways of failing, on the host (its working run is tests/qemu, against the
# real bluetoothd): each one sentence naming what is missing, exit status 2.
source "$(dirname "$0")/ble_lib.sh"

# A name the advertisement cannot carry is refused before anything is registered (the name is
# laid out as a car's local name: 8 bytes, then at most 12 of the name; docs/bluetooth.md).
err=$($PITWALL emulate-car --name "" --duration 1 2>&1); rc=$?
check "empty name: exit status" 2 "$rc"
contains "empty name: says so" "--name: a car's name cannot be empty" "$err"
err=$($PITWALL emulate-car --name "Red Devil Racing" --duration 1 2>&1); rc=$?
check "long name: exit status" 2 "$rc"
contains "long name: names the limit" '"Red Devil Racing" has 16 bytes; a car'"'"'s name has at most 12' "$err"
err=$($PITWALL emulate-car --name $'bad\x01' --plain-name --duration 1 2>&1); rc=$?
check "control character: exit status" 2 "$rc"
contains "control character: says so" "cannot hold control characters (byte 3)" "$err"
err=$($PITWALL emulate-car --name $'R\xc3' --duration 1 2>&1); rc=$?
check "not UTF-8: exit status" 2 "$rc"
contains "not UTF-8: says so" "must be UTF-8: byte 1 is not" "$err"

err=$(DBUS_SYSTEM_BUS_ADDRESS=unix:path=$TMP/nobus $PITWALL emulate-car --duration 1 2>&1); rc=$?
check "no bus: exit status" 2 "$rc"
contains "no bus: says so" "cannot connect to the system bus" "$err"

start_bus
err=$($PITWALL emulate-car --duration 1 2>&1); rc=$?
check "no BlueZ: exit status" 2 "$rc"
contains "no BlueZ: says so" "BlueZ is not running" "$err"

# The fake BlueZ is a central-side fake: adapters without GattManager1, as a controller that
# cannot be a peripheral would be.
start_fake --adapters 1 --cars 0
err=$($PITWALL emulate-car --adapter hci9 --duration 1 2>&1); rc=$?
check "no such adapter: exit status" 2 "$rc"
contains "no such adapter: names it" "BlueZ has no adapter hci9" "$err"
err=$($PITWALL emulate-car --adapter hci0 --duration 1 2>&1); rc=$?
check "no GATT manager: exit status" 2 "$rc"
contains "no GATT manager: says so" "adapter hci0 has no GATT manager" "$err"

finish
