# The MindRoad robot car end to end over loopback sockets (docs/robots.md): the codec from the
# shell, the simulated robot driven by raw bytes (handshake, watchdog, malformed instructions,
# shutdown), Lua scripts over TCP and UDP, and a robot that disappears mid-run and comes back.
source "$(dirname "$0")/lib.sh"
PIDS=()
trap 'for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null; done; rm -rf "$TMP"' EXIT

# start_robot NAME [OPTIONS…]: a sim robot writing NAME.out / NAME.err; sets ROBOT_PID, PORT.
start_robot() {
  local name=$1
  shift
  $PITWALL sim-robot mindroad "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  ROBOT_PID=$!
  PIDS+=("$ROBOT_PID")
  wait_for "$TMP/$name.out" "listening on " || { fail "$name: the robot did not start: $(cat "$TMP/$name.err")"; return 1; }
  PORT=$(sed -n 's/^listening on .*:\([0-9]*\)$/\1/p' "$TMP/$name.out")
}

# ---- the codec from the shell ----
check "encode contact" "10" "$($PITWALL encode mindroad contact)"
check "encode steer full forward (seed §5.1)" "22 7f 00" "$($PITWALL encode mindroad steer 127 0)"
check "encode steer back, half right (seed §5.2)" "22 80 40" "$($PITWALL encode mindroad steer -128 64)"
check "encode click" "32 50 3c" "$($PITWALL encode mindroad click 80 60)"
check "encode buttons by name" "41 01" "$($PITWALL encode mindroad buttons automatic)"
check "encode buttons as a byte" "41 05" "$($PITWALL encode mindroad buttons 0x05)"
check "encode picture mode" "61 01" "$($PITWALL encode mindroad picture-mode hsv)"
check "encode stop, ping, shutdown" "00 50 70" \
  "$($PITWALL encode mindroad stop) $($PITWALL encode mindroad ping) $($PITWALL encode mindroad shutdown)"
err=$($PITWALL encode mindroad click 80 121 2>&1 >/dev/null); rc=$?
check "encode out-of-range exit status" 2 "$rc"
check "encode out-of-range names the range" "pitwall encode: click y 121 is out of range 1..120" "$err"
err=$($PITWALL encode mindroad fly 2>&1 >/dev/null); rc=$?
check "encode unknown exit status" 2 "$rc"
contains "encode unknown lists the forms" "picture-mode rgb|hsv|filter" "$err"

check "decode steering" '{"header":"0x22","id":2,"name":"steering","x":-128,"y":64}' \
  "$($PITWALL decode mindroad 22 80 40)"
check "decode contact" '{"header":"0x10","id":1,"name":"contact"}' "$($PITWALL decode mindroad 0x10)"
check "decode the answer K" '{"byte":"0x4b","name":"contact-answer","text":"K"}' \
  "$($PITWALL decode mindroad 4b)"
check "decode buttons, both readings" \
  '{"button":null,"header":"0x41","id":4,"name":"buttons","pressed":["manual","sensitivity-up"],"raw":5}' \
  "$($PITWALL decode mindroad 41 05)"
err=$($PITWALL decode mindroad a0 2>&1 >/dev/null); rc=$?
check "decode unused id exit status" 2 "$rc"
check "decode unused id names it" \
  "pitwall decode: instruction 10 is unused (ids 8-15 stop the robot; used ids are 0-7), with 0 data bytes" "$err"
err=$($PITWALL decode mindroad 22 7f 2>&1 >/dev/null); rc=$?
check "decode short exit status" 2 "$rc"
check "decode short names the lengths" \
  "pitwall decode: instruction 2 (steering): the header announces 2 data bytes but 1 followed" "$err"
err=$($PITWALL decode mindroad 21 7f 2>&1 >/dev/null)
check "decode wrong length names both" \
  "pitwall decode: instruction 2 (steering) takes 2 data bytes, the header announces 1" "$err"

# ---- bad sim-robot options ----
err=$($PITWALL sim-robot mindroad --listen nowhere 2>&1 >/dev/null); rc=$?
check "--listen without a port exit status" 2 "$rc"
contains "--listen without a port says so" "is not HOST:PORT" "$err"
start_robot busy --duration 20
err=$($PITWALL sim-robot mindroad --listen "127.0.0.1:$PORT" 2>&1 >/dev/null); rc=$?
check "a port in use exit status" 2 "$rc"
contains "a port in use is named" "cannot listen on tcp 127.0.0.1:$PORT" "$err"
kill "$ROBOT_PID"; wait "$ROBOT_PID" 2>/dev/null

# ---- the robot side, driven by raw bytes over TCP ----
start_robot raw --watchdog 0.3 --duration 30
exec 3<>"/dev/tcp/127.0.0.1/$PORT"
printf '\x22\x7f\x00' >&3                        # steering before contact: ignored
wait_for "$TMP/raw.out" '"event":"ignored"' || fail "steering before contact was not ignored"
# contact and steering in one write: under load the shell's turn between two writes may last
# longer than the watchdog's 0.3 s, which would drop the contact before the steering came
printf '\x10\x22\x7f\x00' >&3
answer=$(head -c1 <&3 | od -An -tx1 | tr -d ' ')
check "the robot answers contact with K" "4b" "$answer"
wait_for "$TMP/raw.out" '"event":"steer"' && echo "ok: steering after contact drives" || fail "no steer event"
# no more instructions: the watchdog (0.3 s) stops the robot and drops the contact
wait_for "$TMP/raw.out" '"event":"watchdog"' && echo "ok: the watchdog stops the robot" || fail "no watchdog stop"
contains "after the watchdog: stopped, no contact" '"contact":false,' "$(grep '"event":"watchdog"' "$TMP/raw.out")"
printf '\x22\x7f\x00' >&3                        # ignored until a new contact
wait_for "$TMP/raw.out" '"ignored":2' && echo "ok: steering after the watchdog is ignored" || fail "steering after the watchdog was obeyed"
# a new contact, steering with it; then unused id 9: malformed; then steering, which works
# without a new contact. One write: the watchdog (0.3 s) must not run out while this script
# checks the first (a loaded machine).
printf '\x10\x22\x40\x00\x92\x01\x02\x22\x20\x00' >&3
head -c1 <&3 >/dev/null
wait_for "$TMP/raw.out" '"steer_x":64' && echo "ok: a new contact drives again" || fail "no steering after the new contact"
wait_for "$TMP/raw.out" '"event":"malformed"' || fail "no malformed event"
line=$(grep '"event":"malformed"' "$TMP/raw.out")
contains "a malformed instruction stops the robot" '"moving":false' "$line"
contains "a malformed instruction keeps contact" '"contact":true' "$line"
contains "the log names the malformed instruction" "instruction 9 is unused" "$(cat "$TMP/raw.err")"
wait_for "$TMP/raw.out" '"steer_x":32' && echo "ok: steering after a malformed instruction needs no contact" || fail "steering after malformed was ignored"
printf '\x70' >&3                                # shutdown: the process ends with status 0
wait "$ROBOT_PID"; rc=$?
exec 3>&-
check "shutdown ends the robot with status 0" 0 "$rc"
contains "shutdown is logged" "shut down by the client: exiting" "$(cat "$TMP/raw.err")"
contains "shutdown is a state event" '"event":"shutdown"' "$(cat "$TMP/raw.out")"

# ---- Lua over TCP: handshake, steering, bad input refused with nothing sent ----
start_robot lua --duration 30
cat >"$TMP/drive.lua" <<'LUA'
local robot = pitwall.mindroad { port = tonumber(os.getenv("MINDROAD_PORT")), udp = os.getenv("MINDROAD_UDP") == "1" }
print("contact " .. tostring(robot))  -- ready when made: in contact already
local ok, err = pcall(function() robot:click(161, 10) end)
print("click error: " .. tostring(err))
robot:steer(100, -20)
pitwall.sleep(0.3)
robot:stop()
pitwall.sleep(0.1)
pitwall.stop()
LUA
out=$(MINDROAD_PORT=$PORT timeout 20 $PITWALL run "$TMP/drive.lua" --cars 0 2>"$TMP/drive.err"); rc=$?
check "a Lua script drives the robot: exit status" 0 "$rc"
contains "onContact reaches the script" "contact mindroad tcp 127.0.0.1:$PORT (contact)" "$out"
contains "an out-of-range click names the range" "click x 161 is out of range 1..160; nothing sent" "$out"
robot=$(cat "$TMP/lua.out")
contains "the steering arrived" '"steer_x":100,"steer_y":-20' "$robot"
case "$robot" in *'"event":"click"'*) fail "a refused click reached the robot" ;; *) echo "ok: the refused click sent nothing" ;; esac
contains "stop arrived" '"event":"stop"' "$robot"
kill "$ROBOT_PID"; wait "$ROBOT_PID" 2>/dev/null

# ---- the same over UDP ----
start_robot udp --udp --duration 30
out=$(MINDROAD_PORT=$PORT MINDROAD_UDP=1 timeout 20 $PITWALL run "$TMP/drive.lua" --cars 0 2>"$TMP/udp-drive.err"); rc=$?
check "over UDP: exit status" 0 "$rc"
contains "over UDP: contact" "contact mindroad udp 127.0.0.1:$PORT (contact)" "$out"
contains "over UDP: the steering arrived" '"steer_x":100,"steer_y":-20' "$(cat "$TMP/udp.out")"
kill "$ROBOT_PID"; wait "$ROBOT_PID" 2>/dev/null

# ---- the example survives a robot that disappears mid-run ----
start_robot square --duration 60
MINDROAD_PORT=$PORT MINDROAD_SIDES=3 timeout 50 $PITWALL run "$SRC/examples/mindroad_square.lua" \
  --duration 45 >"$TMP/square.out" 2>"$TMP/square.err" &
RUN_PID=$!
PIDS+=("$RUN_PID")
wait_for "$TMP/square.out" "side 1 of 3 done" 15 || fail "the square did not start: $(cat "$TMP/square.err")"
# The robot dies with steering unread: frozen first, it reads nothing while the script steers
# every 0.1 s, so its death is a reset, not an end of stream (which of the two a plain kill gives
# is a matter of timing; both must read "closed the connection").
kill -STOP "$ROBOT_PID"
unread() { ss -tnH state established "( sport = :$PORT )" | awk '$1 > 0 { found = 1 } END { exit !found }'; }
deadline=$((SECONDS + 10))
until unread || [ $SECONDS -ge $deadline ]; do sleep 0.02; done
unread && echo "ok: the frozen robot has steering unread" || fail "no unread bytes at the robot: $(ss -tn)"
kill -9 "$ROBOT_PID"; wait "$ROBOT_PID" 2>/dev/null
wait_for "$TMP/square.out" "lost contact: tcp 127.0.0.1:$PORT" 5 &&
  echo "ok: onLost reaches the script with a clear reason" || fail "onLost did not reach the script: $(cat "$TMP/square.out")"
contains "the loss is logged" "closed the connection; retrying in 0.5 s" "$(cat "$TMP/square.err")"
start_robot square2 --listen "127.0.0.1:$PORT" --duration 60
wait "$RUN_PID"; rc=$?
check "the example ends normally after the robot came back" 0 "$rc"
out=$(cat "$TMP/square.out")
check "onContact again after the robot came back" 2 "$(grep -c ': contact$' <<<"$out")"
contains "the square was finished" "square done" "$out"
contains "the new robot was driven" '"event":"steer"' "$(cat "$TMP/square2.out")"
case "$(cat "$TMP/square.err")" in *"error "*) fail "the example reported an error: $(cat "$TMP/square.err")" ;; *) echo "ok: no script error" ;; esac

finish
