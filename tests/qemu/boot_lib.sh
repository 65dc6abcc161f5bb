# The QEMU guest every tests/qemu test boots (tests/qemu/README.md), sourced by ble_e2e.sh and
# gamepad_e2e.sh: Debian's 6.1 amd64 kernel (fetched once with `apt-get download`, extracted, only
# vmlinuz and the modules the tests load kept in qemu-cache/ next to the pitwall binary), an
# initramfs of busybox that loads a test's modules, mounts the host's `/` read-only over 9p and
# runs the test's guest script chrooted into it, and one TCG boot whose exit status the guest
# prints on the console.
#
# The sourcing script (source "$(dirname "${BASH_SOURCE[0]}")/boot_lib.sh", first thing) calls:
#   skip REASON / fail REASON        exit 77 (ctest: skipped) / exit 1, saying why
#   qemu_args USAGE "$@"             its arguments: as many as USAGE has words, the first two
#                                    PITWALL_BINARY SOURCE_DIR (PITWALL and SRC, absolute, set
#                                    here), else USAGE and exit 2
#   qemu_check_host PACKAGE...       skips without x86_64 or without one of the Debian packages
#   qemu_kernel SET                  the kernel and SET's modules (QEMU_MODULE_SETS below)
#   qemu_initrd SET TMPFS GUEST...   the initramfs: SET's modules loaded, the folders in TMPFS
#                                    (space-separated) writable tmpfs, then GUEST... (a command
#                                    and its arguments, run as root in the chroot with a clean
#                                    environment plus QEMU_GUEST_ENV, "NAME=value" words)
#   status=$(qemu_boot LABEL)        one boot; the guest's exit status (empty: it gave none)
#   qemu_result STATUS PASS FAILED   the script's end: exit 0 saying PASS, 77, or fail saying FAILED
# PITWALL_QEMU_TIMEOUT: seconds before QEMU is killed, boot included (default 180).

# Modules each test's guest loads (their dependencies come from the kernel's own modules.dep).
# One cache holds the modules of every set, so that the tests share one kernel download.
declare -A QEMU_MODULE_SETS=(
  # Without the AF_ALG ones btvirt fails with a misleading "Failed to open Virtual HCI device".
  [ble]="crc16 ecc rfkill ecdh_generic bluetooth hci_vhci af_alg algif_hash algif_skcipher cmac
    ecb virtio_pci 9pnet_virtio 9p"
  # /dev/uinput makes a kernel input device that evdev shows as /dev/input/eventN.
  [gamepad]="uinput evdev virtio_pci 9pnet_virtio 9p"
)
QEMU_TIMEOUT=${PITWALL_QEMU_TIMEOUT:-180}
declare -p QEMU_GUEST_ENV >/dev/null 2>&1 || QEMU_GUEST_ENV=()
QEMU_RUN='' QEMU_FETCH=''  # scratch folders in the cache, removed however the script ends
trap 'rm -rf "$QEMU_RUN" "$QEMU_FETCH"' EXIT

skip() {
  echo "SKIP: $*"
  exit 77
}
fail() {
  echo "FAIL: $*"
  exit 1
}

qemu_args() {  # qemu_args USAGE "$@"
  local usage=$1 words
  shift
  read -r -a words <<<"$usage"
  [ $# -eq ${#words[@]} ] || { echo "usage: $0 $usage" >&2; exit 2; }
  PITWALL=$(realpath "$1")
  SRC=$(realpath "$2")
  [ -x "$PITWALL" ] || fail "no pitwall binary at $1"
}

qemu_check_host() {  # qemu_check_host PACKAGE...: skips without x86_64 or without a package
  [ "$(uname -m)" = x86_64 ] ||
    skip "the guest kernel is Debian's amd64 one; this machine is $(uname -m)"
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] || skip "missing Debian packages: ${missing[*]} (./dev installs them)"
}

QEMU_CACHE=''
QEMU_KERNEL=''
qemu_fetch_kernel() {
  local work=$QEMU_CACHE/fetch.$$ names name version ok= set m deps ko
  QEMU_FETCH=$work
  rm -rf "$work" && mkdir -p "$work" || fail "cannot write the kernel cache $QEMU_CACHE"
  names=$(apt-cache search --names-only '^linux-image-6\.1\.0-[0-9]+-amd64$' | cut -d' ' -f1 |
    sort -V -r)
  [ -n "$names" ] || skip "apt offers no linux-image-6.1.0-*-amd64 (run apt-get update)"
  for name in $names; do  # the newest that the archive still has
    echo "qemu: fetching $name" >&2
    (cd "$work" && apt-get download -q "$name" >/dev/null 2>&1) && { ok=1; break; }
  done
  [ -n "$ok" ] || skip "none of ${names//$'\n'/ } could be downloaded from Debian"
  dpkg -x "$work"/*.deb "$work/x" || fail "dpkg -x failed on $(ls "$work"/*.deb)"
  version=${name#linux-image-}
  depmod -b "$work/x" "$version" || fail "depmod failed on the extracted $version"
  mkdir -p "$work/kernel/modules"
  cp "$work/x/boot/vmlinuz-$version" "$work/kernel/vmlinuz"
  for set in "${!QEMU_MODULE_SETS[@]}"; do
    deps=''
    for m in ${QEMU_MODULE_SETS[$set]}; do
      deps+=$(modprobe -d "$work/x" -S "$version" --show-depends "$m") ||
        fail "kernel $version has no module $m"
      deps+=$'\n'
    done
    # `insmod PATH` lines in load order; built-in modules print `builtin NAME` and need nothing.
    : >"$work/kernel/load-order.$set"
    for ko in $(echo "$deps" | awk '$1 == "insmod" && !seen[$2]++ { print $2 }'); do
      cp "$ko" "$work/kernel/modules/" && basename "$ko" >>"$work/kernel/load-order.$set"
    done
  done
  echo "$version" >"$work/kernel/version"
  rm -rf "$QEMU_KERNEL" && mv "$work/kernel" "$QEMU_KERNEL"
  rm -rf "$work"
}

qemu_kernel() {  # qemu_kernel SET
  QEMU_CACHE=$(dirname "$PITWALL")/qemu-cache
  QEMU_KERNEL=$QEMU_CACHE/kernel  # vmlinuz, modules/*.ko, load-order.SET, version
  [ -n "${QEMU_MODULE_SETS[$1]:-}" ] || fail "no module set '$1' in boot_lib.sh"
  # (a cache made before the sets, or without this one, is made again)
  [ -f "$QEMU_KERNEL/load-order.$1" ] && [ -f "$QEMU_KERNEL/vmlinuz" ] || qemu_fetch_kernel
  echo "qemu: kernel $(cat "$QEMU_KERNEL/version") from $QEMU_KERNEL" >&2
}

qemu_initrd() {  # qemu_initrd SET TMPFS GUEST...
  local set=$1 tmpfs=$2 guest word
  shift 2
  guest=$(printf '%q ' "$@")
  local env=''
  for word in "${QEMU_GUEST_ENV[@]}"; do env+=$(printf '%q ' "$word"); done
  QEMU_RUN=$(mktemp -d "$QEMU_CACHE/run.XXXXXX")
  mkdir -p "$QEMU_RUN/root/bin" "$QEMU_RUN/root/modules" "$QEMU_RUN/root/proc" \
    "$QEMU_RUN/root/sys" "$QEMU_RUN/root/dev" "$QEMU_RUN/root/host"
  cp /bin/busybox "$QEMU_RUN/root/bin/busybox"
  for word in $(cat "$QEMU_KERNEL/load-order.$set"); do
    cp "$QEMU_KERNEL/modules/$word" "$QEMU_RUN/root/modules/"
  done
  cp "$QEMU_KERNEL/load-order.$set" "$QEMU_RUN/root/modules/load-order"
  cat >"$QEMU_RUN/root/init" <<EOF
#!/bin/busybox sh
# The guest's PID 1: modules, the host tree, then the test's guest script chrooted into it. Its
# status goes to the console in a marker line the host parses; then power off.
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
echo "init: kernel up after \$(cut -d' ' -f1 /proc/uptime) s"
mount -t sysfs sys /sys; mount -t devtmpfs dev /dev
for m in \$(cat /modules/load-order); do
  insmod /modules/\$m 2>/dev/null || echo "init: insmod \$m failed"
done
rc=1
if mount -t 9p -o trans=virtio,version=9p2000.L,ro,msize=512000,cache=loose host /host; then
  mount -t proc proc /host/proc && mount -t sysfs sys /host/sys && mount -t devtmpfs dev /host/dev
  ln -s /proc/self/fd /host/dev/fd
  # Writable scratch for the guest; where the source tree or the binary lives below one of these
  # folders (a clone in /tmp or /root), that folder's entry is bound back in, read-only still.
  for d in $tmpfs; do
    [ -d /host\$d ] || continue
    mkdir -p /orig\$d && mount -o bind /host\$d /orig\$d
    mount -t tmpfs tmpfs /host\$d
    for p in "$SRC" "$(dirname "$PITWALL")"; do
      case "\$p" in
        \$d/*)
          top=\${p#\$d/}; top=\${top%%/*}
          mkdir -p "/host\$d/\$top" && mount -o bind "/orig\$d/\$top" "/host\$d/\$top"
          ;;
      esac
    done
  done
  chroot /host /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \\
    HOME=/root TERM=dumb $env $guest
  rc=\$?
  echo "init: guest done after \$(cut -d' ' -f1 /proc/uptime) s"
else
  echo "init: cannot mount the host tree over 9p"
fi
echo "PITWALL-QEMU-EXIT=\$rc"
poweroff -f
EOF
  chmod +x "$QEMU_RUN/root/init"
  (cd "$QEMU_RUN/root" && find . | cpio -o -H newc --quiet | gzip -1 >"$QEMU_RUN/initrd") ||
    fail "cannot build the initramfs"
}

# TCG, not KVM: KVM hangs at boot on these machines (docs in the notes). The serial console is
# the guest's stdout; `quiet` keeps the kernel's own lines out of it.
# One boot: its guest's exit status on stdout's last line (empty when it gave none).
qemu_boot() {  # qemu_boot LABEL
  echo "qemu: booting ($1, timeout ${QEMU_TIMEOUT}s)" >&2
  local start ms elapsed qemu_rc status
  start=$(date +%s%N)
  timeout --kill-after=5 "$QEMU_TIMEOUT" qemu-system-x86_64 -accel tcg,thread=multi -cpu max \
    -m 1024 -smp 2 -nographic -no-reboot -nodefaults -serial stdio -net none \
    -kernel "$QEMU_KERNEL/vmlinuz" -initrd "$QEMU_RUN/initrd" \
    -append "console=ttyS0 quiet loglevel=3 panic=-1" \
    -virtfs local,path=/,mount_tag=host,security_model=none,readonly=on,multidevs=remap \
    </dev/null 2>&1 | tee "$QEMU_RUN/console" >&2
  qemu_rc=${PIPESTATUS[0]}
  ms=$((($(date +%s%N) - start) / 1000000))
  elapsed=$((ms / 1000)).$(printf %03d $((ms % 1000)))
  status=$(tr -d '\r' <"$QEMU_RUN/console" | sed -n 's/^PITWALL-QEMU-EXIT=\([0-9]*\)$/\1/p' |
    tail -n1)
  echo "qemu: guest finished in ${elapsed}s (QEMU status $qemu_rc)" >&2
  echo "$status"
}

# The guest's status (from qemu_boot) made the script's: 0 printing "PASS: " and PASS, 77 (the
# guest skipped), or fail with FAILED and the status.
qemu_result() {  # qemu_result STATUS PASS FAILED
  [ -n "$1" ] ||
    fail "the guest gave no exit status (QEMU status 124 = killed after ${QEMU_TIMEOUT}s)"
  [ "$1" = 77 ] && exit 77
  [ "$1" = 0 ] && { echo "PASS: $2"; exit 0; }
  fail "$3 (status $1)"
}
