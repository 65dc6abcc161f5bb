#!/usr/bin/env bash
# Runs inside the QEMU guest of tests/qemu/gamepad_e2e.sh, chrooted into the host's tree
# (read-only; /tmp is tmpfs), as root, with uinput and evdev loaded: real kernel input devices
# made by uinput_pad drive car 1 of the simulator through `pitwall run --humans 1 --gamepads`;
# a pad whose ABS_RZ rests mid-range does not drive until that axis is seen at its minimum.
# Exit status: 0 passed, 1 failed (with the last lines of each log).
#
#   gamepad_guest.sh PITWALL SOURCE_DIR UINPUT_PAD
set -uo pipefail
PITWALL=$1
SRC=$2
PAD=$3
source "$SRC/tests/qemu/guest_lib.sh"  # LOGS, say, fail, until_ok

# wait_line FILE PATTERN SECONDS: until a line of FILE matches PATTERN (grep -E); false if never.
wait_line() { until_ok "$3" grep -qE "$2" "$1"; }
# after FILE: the lines written to FILE from now on are the ones `wait_new` looks at
mark() { wc -l <"$1"; }
new_match() { tail -n +"$(($2 + 1))" "$1" | grep -E "$3" > /dev/null; }  # new_match FILE MARK PATTERN
wait_new() { until_ok "$4" new_match "$1" "$2" "$3"; }  # wait_new FILE MARK PATTERN SECONDS

[ -c /dev/uinput ] || fail "no /dev/uinput in the guest (the uinput module did not load)"
mkdir -p /dev/input

# pad NAME: a virtual gamepad fed through a FIFO on fd 3 (A), 4 (B) or 5 (C), its output in a log
plug() {  # plug FD NAME [RZ]
  mkfifo "/tmp/pad$1.in"
  "$PAD" "$2" ${3:-} <"/tmp/pad$1.in" >"$LOGS/pad$1.log" 2>&1 &
  eval "exec $1>/tmp/pad$1.in"
  wait_line "$LOGS/pad$1.log" '^device /dev/input/event' 10 || fail "uinput_pad '$2' made no device"
  say "plugged in: $2 at $(sed -n 's/^device //p' "$LOGS/pad$1.log")"
}

# ---- pad A, there before pitwall starts (found by the scan of /dev/input) ----
plug 3 "Pad A"

RUN=$LOGS/run.log
# --budget 2: the emulated CPU (TCG) loads the race library slower than 100 ms
"$PITWALL" run "$SRC/tests/integration/human_seat1.lua" --humans 1 --gamepads --duration 60 \
  --budget 2 >"$RUN" 2>&1 &
PID=$!
wait_line "$RUN" 'seat 1: holder=gamepad' 20 || fail "pad A took no seat"
grep -q 'gamepad "Pad A" at /dev/input/event[0-9]*: throttle on ABS_RZ' "$RUN" ||
  fail "pitwall did not name pad A and its trigger"
say "pad A holds seat 1"

m=$(mark "$RUN")
echo "axis 5 255" >&3  # the right trigger all the way
wait_new "$RUN" "$m" 'throttle=1.00 speed=[0-9]+ moving=yes' 20 || fail "the trigger did not drive car 1"
say "trigger pulled: car 1 drives"

m=$(mark "$RUN")
echo "key 304 1" >&3  # BTN_SOUTH: brake
wait_new "$RUN" "$m" 'throttle=0.00 .* truth=0$' 20 || fail "BTN_SOUTH did not stop car 1"
echo "key 304 0" >&3  # let go of the brake: the trigger, still pulled, counts again
wait_new "$RUN" "$m" 'throttle=1.00 .* moving=yes' 20 || fail "car 1 did not drive after the brake"
say "BTN_SOUTH braked car 1 to a stop, and it drove on when let go"

m=$(mark "$RUN")
echo "unplug" >&3  # the trigger still pulled: the car must stop all the same
exec 3>&-
wait_new "$RUN" "$m" 'the gamepad was unplugged' 10 || fail "pitwall did not see pad A unplugged"
wait_new "$RUN" "$m" 'holder=nil throttle=0.00 .* truth=0$' 20 ||
  fail "car 1 did not slow to a stop after pad A was unplugged"
say "pad A unplugged with its trigger held: seat 1 free, car 1 stopped"

# ---- pad B, plugged in while pitwall runs (inotify: hot-plug) ----
m=$(mark "$RUN")
plug 4 "Pad B"
wait_new "$RUN" "$m" 'seat 1: holder=gamepad' 20 || fail "pad B, plugged in later, took no seat"
echo "axis 5 128" >&4
wait_new "$RUN" "$m" 'throttle=0.50 .* moving=yes' 20 || fail "pad B's trigger did not drive car 1"
say "pad B plugged in while running: holds seat 1, half trigger drives car 1"

# ---- pad C: ABS_RZ rests mid-range (a hid-generic pad's right stick), not a trigger ----
m=$(mark "$RUN")
echo "axis 5 0" >&4
echo "unplug" >&4
exec 4>&-
# at rest by the simulator's own speed: `moving` says no while a car rolls without reporting
wait_new "$RUN" "$m" 'holder=nil throttle=0.00 .* truth=0$' 20 || fail "car 1 did not stop after pad B"
m=$(mark "$RUN")
plug 5 "Pad C" 128
wait_new "$RUN" "$m" 'seat 1: holder=gamepad' 20 || fail "pad C took no seat"
grep -q 'gamepad "Pad C": ABS_RZ does not rest at its minimum (128 in 0..255' "$RUN" ||
  fail "pitwall did not say that pad C's ABS_RZ is not used"
echo "key 304 1" >&5  # A pressed and let go: the brake lets go to 0, not to the stick's half
echo "key 304 0" >&5
echo "axis 5 200" >&5  # the right stick moved about, never to its minimum
sleep 2
tail -n +"$((m + 1))" "$RUN" | grep -E 'seat 1: holder=gamepad throttle=0\.[1-9]|truth=[1-9]' > /dev/null &&
  fail "pad C's resting ABS_RZ drove car 1"
m=$(mark "$RUN")
echo "key 313 1" >&5  # BTN_TR2 drives meanwhile
wait_new "$RUN" "$m" 'throttle=1.00 .* moving=yes' 20 || fail "pad C's BTN_TR2 did not drive car 1"
echo "key 313 0" >&5
echo "axis 5 0" >&5  # seen at its minimum: from now on the throttle
wait_new "$RUN" "$m" 'gamepad "Pad C": ABS_RZ rests at its minimum' 20 ||
  fail "pad C's ABS_RZ at its minimum was not taken as the trigger"
m=$(mark "$RUN")
echo "axis 5 255" >&5
wait_new "$RUN" "$m" 'throttle=1.00 .* moving=yes' 20 || fail "pad C's ABS_RZ did not drive car 1"
say "pad C: ABS_RZ resting at 128 drove nothing (A pressed and let go, moved), BTN_TR2 did;" \
  "seen at 0 it is the trigger"

kill -TERM "$PID"
wait "$PID"
status=$?
[ "$status" -eq 130 ] || fail "pitwall run exited with status $status after SIGTERM, not 130 (docs/cli.md)"
grep -q 'seat 1: the gamepad was unplugged; its car slows to a stop' "$RUN" ||
  fail "the seat's log did not say why car 1 was stopped"
echo "unplug" >&5
exec 5>&-
wait
say "passed: a uinput gamepad drives car 1, unplugging it stops the car, a new one is picked up"
exit 0
