# What every guest script of tests/qemu shares (guest.sh, gamepad_guest.sh), sourced inside the
# QEMU guest from the host's tree (read-only over 9p; /tmp is tmpfs) as
#   source "$SRC/tests/qemu/guest_lib.sh"
# Gives LOGS (/tmp/logs, made here: each log a test keeps there is named *.log) and:
#   say TEXT...                 a line on the console, timed from when this file was sourced
#   fail TEXT...                says FAIL and the last lines of each $LOGS/*.log, then exits
#                               $FAIL_STATUS (default 1; 75: the emulation's failure, not pitwall's)
#   until_ok SECONDS COMMAND... retries every 50 ms; false when it never succeeded
LOGS=/tmp/logs
mkdir -p "$LOGS"
T0=$(date +%s%N)

say() {
  local ms=$((($(date +%s%N) - T0) / 1000000))
  printf '[guest %3d.%03d] %s\n' $((ms / 1000)) $((ms % 1000)) "$*"
}
fail() {
  if [ "${FAIL_STATUS:-1}" = 75 ]; then say "FAIL (the emulation's): $*"; else say "FAIL: $*"; fi
  for log in "$LOGS"/*.log; do
    [ -s "$log" ] || continue
    echo "---- last lines of $(basename "$log")"
    tail -n 25 "$log"
  done
  exit "${FAIL_STATUS:-1}"
}
until_ok() {
  local deadline=$(($(date +%s%N) + $1 * 1000000000))
  shift
  while ! "$@" >/dev/null 2>&1; do
    [ "$(date +%s%N)" -lt "$deadline" ] || return 1
    sleep 0.05
  done
}
