#!/usr/bin/env bash
# How flaky the QEMU test is (tests/qemu/README.md "A failed boot"): boots the guest of
# ble_e2e.sh N times (default 20), one after the other, and counts the outcomes by cause — the
# guest's exit status and its first FAIL line.
#
#   tests/qemu/qemu_flakiness.sh PITWALL_BINARY SOURCE_DIR [N]
#
# Each boot's whole output is kept in ./qemu-flakiness/boot-K.log. Exit status 0 when every boot
# passed, 1 otherwise.
set -uo pipefail
[ $# -ge 2 ] || { echo "usage: $0 PITWALL_BINARY SOURCE_DIR [N]" >&2; exit 2; }
PITWALL=$1 SRC=$2 N=${3:-20}
OUT=$PWD/qemu-flakiness
mkdir -p "$OUT"
declare -A causes=()
failed=0
for k in $(seq 1 "$N"); do
  start=$SECONDS
  # one boot, no second one: the guest's own status is what is counted
  PITWALL_QEMU_RETRY=0 bash "$SRC/tests/qemu/ble_e2e.sh" "$PITWALL" "$SRC" >"$OUT/boot-$k.log" 2>&1
  rc=$?
  status=$(sed -n 's/^PITWALL-QEMU-EXIT=\([0-9]*\).*/\1/p' "$OUT/boot-$k.log" | tail -1)
  why=$(grep -m1 -E '\] FAIL' "$OUT/boot-$k.log" | sed 's/^\[guest *[0-9.]*\] //')
  case "$rc" in
    0) cause="passed" ;;
    77) cause="skipped: $(grep -m1 -i skip "$OUT/boot-$k.log")" ;;
    *) cause="status ${status:-none}: ${why:-no FAIL line (see boot-$k.log)}"; failed=$((failed + 1)) ;;
  esac
  causes[$cause]=$((${causes[$cause]:-0} + 1))
  echo "boot $k: $cause ($((SECONDS - start)) s)"
done
echo "--- $N boots, $(date -u +%Y-%m-%d), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg):"
for c in "${!causes[@]}"; do printf '%4d  %s\n' "${causes[$c]}" "$c"; done | sort -rn
[ "$failed" -eq 0 ]
