# pitwall emulate-car's ways of failing, on the host (its working run is tests/qemu, against the
# real bluetoothd): each one sentence naming what is missing, exit status 2.
source "$(dirname "$0")/ble_lib.sh"

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
