#!/usr/bin/env bash
# pitwall against the REAL bluetoothd, end to end, in a QEMU guest (docs: tests/qemu/README.md).
#
#   tests/qemu/ble_e2e.sh PITWALL_BINARY SOURCE_DIR
#
# The host kernel here has no Bluetooth, so a TCG guest runs Debian's 6.1 kernel with the host's
# `/` shared read-only over 9p: inside, a private dbus-daemon, `btvirt -l2` (two emulated LE
# controllers that hear each other), `bluetoothd -n -E`, then `pitwall emulate-car` advertising
# an Anki car on hci0 and a central on hci1 (tests/qemu/guest.sh). The guest's exit status is the
# script's. Exit 77 (ctest: skipped) when it cannot run here, always saying why.
set -uo pipefail
# skip, fail, the arguments, the kernel, the initramfs and the boot (shared with gamepad_e2e.sh)
source "$(dirname "${BASH_SOURCE[0]}")/boot_lib.sh"

# Who plays the central on hci1 (PITWALL_QEMU_CENTRAL): one or more of these, separated by
# commas, one after the other against the same car in one boot (default bleak,pitwall,links):
#   bleak    `pitwall scan` must show the car's name clean, with its state and version; then a
#            client on Debian's bleak that behaves as py-drivesdk does (central_drivesdk.py): it
#            finds the car by py-drivesdk's name rules, drives it with py-drivesdk's short
#            set-speed, changes lane, pings, asks version and battery, stops it.
#   pitwall  `pitwall run tests/qemu/laps_ble.lua --ble --adapter hci1 --car ADDR --duration 30`: the car
#            is found, connected and driven 2 laps.
#   tools    BlueZ's own bluetoothctl, no pitwall code on the central side: sees the
#            advertisement (service UUID, manufacturer data, name), connects, subscribes, writes
#            a ping `01 16`, expects the notification `01 17`, disconnects and does it again.
#   both     tools,pitwall (a reconnection by another central).
#   links    `pitwall run tests/qemu/links_ble.lua` drives the car while hci1 is powered off for
#            3 s, then bluetoothd is restarted: the car must drive again after each, within a
#            bound (docs/bluetooth.md "What survives what").
#   script:FILE  a developer's own check, sourced inside the guest by guest.sh.
CENTRAL=${PITWALL_QEMU_CENTRAL:-bleak,pitwall,links}
# Debian packages the harness needs (installed by the project's ./dev, never by this script).
PACKAGES=(qemu-system-x86 busybox-static cpio kmod bluez bluez-test-tools dbus-daemon dbus-bin)
[[ ",$CENTRAL," == *,bleak,* ]] && PACKAGES+=(python3-bleak)

qemu_args "PITWALL_BINARY SOURCE_DIR" "$@"
IFS=, read -r -a centrals <<<"$CENTRAL"
[ ${#centrals[@]} -gt 0 ] || fail "PITWALL_QEMU_CENTRAL is empty"
for c in "${centrals[@]}"; do
  case "$c" in
    bleak | pitwall | tools | both | links | script:?*) ;;
    *) fail "PITWALL_QEMU_CENTRAL: '$c' is none of bleak, pitwall, tools, both, links, script:FILE" ;;
  esac
done

qemu_check_host "${PACKAGES[@]}"
BLUETOOTHD=
for b in /usr/libexec/bluetooth/bluetoothd /usr/lib/bluetooth/bluetoothd /usr/sbin/bluetoothd; do
  [ -x "$b" ] && { BLUETOOTHD=$b; break; }
done
[ -n "$BLUETOOTHD" ] || skip "no bluetoothd binary found (package bluez)"

qemu_kernel ble
QEMU_GUEST_ENV=(PITWALL_QEMU_LOG="${PITWALL_QEMU_LOG:-info}")
# /var/lib/bluetooth: bluetoothd's state
qemu_initrd ble "/tmp /run /var/lib/bluetooth /root" \
  /bin/bash "$SRC/tests/qemu/guest.sh" "$PITWALL" "$SRC" "$CENTRAL" "$BLUETOOTHD"

# A boot is booted once more only when the guest shows its failure is the emulation's: status 75,
# either before any pitwall code took part (the private bus, btvirt, bluetoothd, the adapters'
# power) or a central that failed while BlueZ's own btmgmt on hci1 could not hear hci0's
# advertisement either (guest.sh, radios_deaf). Every other failure fails the test at once
# (tests/qemu/README.md "A failed boot"; qemu_flakiness.sh counts them by cause).
status=$(qemu_boot "central: $CENTRAL")
if [ "$status" = 75 ] && [ "${PITWALL_QEMU_RETRY:-1}" != 0 ]; then
  echo "qemu: the guest's failure was the emulation's (status 75, see above); booting once more"
  status=$(qemu_boot "central: $CENTRAL")
fi
qemu_result "$status" "central '$CENTRAL' against the real bluetoothd" \
  "the guest's checks failed twice"
