# The stop that does not need the loop, for the robots the fleet does not hold (docs/safety.md):
# an Alphabot over WLAN (its own TCP socket: the stop frame goes on it, whole, from the
# watchdog's thread) and over BLE (the fake BlueZ: a WriteValue on a bus connection of the
# watchdog's own), and Ctrl-Z, which stops them before the process stops. The adversary is a
# script that drives the robot every 20 ms and then wedges the loop in C code (a pattern that
# backtracks for hours).
source "$(dirname "$0")/ble_lib.sh"
PIDS=()
trap 'for pid in "${PIDS[@]}"; do kill -9 "$pid" 2>/dev/null; done; cleanup_ble' EXIT

cat >"$TMP/robot.lua" <<'LUA'
local where = os.getenv("PORT") and {host = "127.0.0.1", port = tonumber(os.getenv("PORT"))}
  or {ble = "AB:00:00:00:00:01"}
local r = pitwall.alphabot(where)
assert(pitwall.waitUntil(function() return r.connected end, 10), "never connected: " .. tostring(r.lastError))
pitwall.every(0.02, function() r:drive(40, 0) end)
r:drive(40, 0)
pitwall.sleep(0.3)
print("driving")
io.stdout:flush()
if os.getenv("MODE") == "wedge" then
  print("wedging")
  io.stdout:flush()
  string.find(string.rep("a", 5000), ".-.-.-.-.-b")
end
LUA

# run_bg NAME ENV…: robot.lua in the background, its stdout on fd 4 (run_fifo)
run_bg() {
  local name=$1
  shift
  run_fifo "$name" env "$@" $PITWALL run "$TMP/robot.lua" --cars 0
  PIDS+=($RUN_PID)
}

# sim_robot: `pitwall sim-robot alphabot` on a free port; sets PORT, ROBOT_PID and ROBOT (its
# files: each robot its own, as a file named again is truncated by the new robot's shell only
# after this one may have read the old robot's port from it)
ROBOTS=0
sim_robot() {
  ROBOTS=$((ROBOTS + 1))
  ROBOT="$TMP/robot$ROBOTS"
  $PITWALL sim-robot alphabot >"$ROBOT.out" 2>"$ROBOT.err" &
  ROBOT_PID=$!
  PIDS+=($ROBOT_PID)
  wait_for "$ROBOT.out" "listening on" 30 || fail "sim-robot did not start: $(cat "$ROBOT.err")"
  PORT=$(sed -n 's/^listening on .*:\([0-9]*\)$/\1/p' "$ROBOT.out")
}
# stop_robot: interrupts the simulated robot, which then says what it was last told
stop_robot() {
  kill -INT $ROBOT_PID
  wait_bounded $ROBOT_PID
}
robot_state() { sed -n 's/.*\(the robot is [a-z ]*\)$/\1/p' "$ROBOT.err"; }

# --- WLAN, the watchdog: the loop wedged; nobody sends a signal
sim_robot
run_bg wlan-watchdog PORT=$PORT MODE=wedge
expect_wedged wlan-watchdog
contains "wlan watchdog: stderr says it stopped the robot" "the watchdog sent 1 car its stop" \
  "$(cat "$TMP/wlan-watchdog.err")"
stop_robot
check "wlan watchdog: the robot was stopped while the loop was stuck" "the robot is at rest" \
  "$(robot_state)"
end_fifo

# --- WLAN, the control: the same run without a wedge leaves a moving robot to the interrupt
sim_robot
run_bg wlan-control PORT=$PORT MODE=none
stop_robot
check "wlan control: a robot the script drives is moving" "the robot is moving" "$(robot_state)"
end_fifo

# --- WLAN, Ctrl-Z: the robot is stopped before the process stops
sim_robot
run_bg wlan-tstp PORT=$PORT MODE=none
cat <&4 >/dev/null 2>&1 &
kill -TSTP $RUN_PID
wait_suspended $RUN_PID
stop_robot
check "wlan Ctrl-Z: the robot was stopped before the process stopped" "the robot is at rest" \
  "$(robot_state)"
kill -CONT $RUN_PID
kill -INT $RUN_PID
wait_bounded $RUN_PID
check "wlan Ctrl-Z, fg, Ctrl-C: exit status" 130 $?
exec 4<&-

# --- BLE, the watchdog: the fake BlueZ's summary says what the robot was last told
start_bus
start_fake --cars 0 --alphabots 1
run_bg ble-watchdog MODE=wedge
expect_wedged ble-watchdog
contains "ble watchdog: stderr says it stopped the robot" "the watchdog sent 1 car its stop" \
  "$(cat "$TMP/ble-watchdog.err")"
stop_fake  # while pitwall is still wedged
contains "ble watchdog: the robot was stopped while the loop was stuck" "speed=0" \
  "$(grep "^AB:00:00:00:00:01" "$TMP/fake.out")"
end_fifo

# --- BLE, the control: without the wedge the fake's robot is left driving when pitwall dies
start_fake --cars 0 --alphabots 1
run_bg ble-control MODE=none
end_fifo
stop_fake
contains "ble control: a robot the script drives is left at its speed" "speed=40" \
  "$(grep "^AB:00:00:00:00:01" "$TMP/fake.out")"

finish
