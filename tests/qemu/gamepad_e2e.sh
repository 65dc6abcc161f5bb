#!/usr/bin/env bash
# Gamepads end to end with REAL kernel input devices, in a QEMU guest (tests/qemu/README.md).
#
#   tests/qemu/gamepad_e2e.sh PITWALL_BINARY SOURCE_DIR UINPUT_PAD_BINARY
#
# The host kernel here has no /dev/uinput, so the guest of boot_lib.sh (Debian's 6.1 kernel, the
# host's `/` read-only over 9p) loads uinput and evdev; inside (tests/qemu/gamepad_guest.sh),
# uinput_pad makes virtual gamepads that evdev shows in /dev/input like any USB pad, and
# `pitwall run --humans 1 --gamepads` drives car 1 of the simulator with them: the trigger
# drives, BTN_SOUTH brakes, unplugging stops the car, a pad plugged in later takes the seat.
# No Bluetooth, no D-Bus: the lightest guest. Exit 77 (ctest: skipped) when it cannot run here,
# always saying why.
set -uo pipefail
# skip, fail, the arguments, the kernel, the initramfs and the boot (shared with ble_e2e.sh)
source "$(dirname "${BASH_SOURCE[0]}")/boot_lib.sh"
PACKAGES=(qemu-system-x86 busybox-static cpio kmod)

qemu_args "PITWALL_BINARY SOURCE_DIR UINPUT_PAD_BINARY" "$@"
PAD=$(realpath "$3")
[ -x "$PAD" ] || fail "no uinput_pad binary at $3"

qemu_check_host "${PACKAGES[@]}"
qemu_kernel gamepad
qemu_initrd gamepad "/tmp /run /root" \
  /bin/bash "$SRC/tests/qemu/gamepad_guest.sh" "$PITWALL" "$SRC" "$PAD"
status=$(qemu_boot "gamepads")
qemu_result "$status" \
  "uinput gamepads drive car 1; unplugged, it stops; a resting mid-range ABS_RZ does not drive" \
  "the guest's checks failed"
