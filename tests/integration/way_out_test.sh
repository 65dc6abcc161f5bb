# Every way out still ends in a stop (docs/safety.md), on the simulator with --record, against
# tests/integration/nagging.lua, which commands its cars every 20 ms:
# - a reader that goes away (`| head -n 2`): the stop path, status 141, the record flushed
# - Ctrl-Z: the cars stop before the process stops; fg resumes the engine, not the cars
# - a start that is refused leaves an old record byte for byte as it was
source "$(dirname "$0")/lib.sh"
NAGGING="$SRC/tests/integration/nagging.lua"

# --- a reader that goes away: head takes two lines of a script that prints on every position
# update, and quits; the next print meets a closed pipe
CHATTY=1 MODE=none $PITWALL run "$NAGGING" --cars 2 --record "$TMP/pipe.jsonl" \
  2>"$TMP/pipe.err" | head -n 2 >"$TMP/pipe.out"
statuses=("${PIPESTATUS[@]}")
check "| head: pitwall ends with the status of a closed pipe, after the stop path" 141 \
  "${statuses[0]}"
check "| head: head had its two lines" 2 "$(wc -l <"$TMP/pipe.out")"
contains "| head: the log says why the run ended" "the output's reader went away" \
  "$(cat "$TMP/pipe.err")"
expect_stopped "| head" "$TMP/pipe.jsonl" 2
# the whole record parses: it was flushed, not cut by a death
python3 -c 'import json,sys; [json.loads(l) for l in open(sys.argv[1])]' "$TMP/pipe.jsonl"
check "| head: every line of the record parses" 0 $?

# stdout and stderr both into the pipe: the log has nowhere to go either, and the run still stops
CHATTY=1 MODE=none $PITWALL run "$NAGGING" --cars 2 --record "$TMP/pipe2.jsonl" 2>&1 |
  head -n 2 >/dev/null
check "2>&1 | head: status 141" 141 "${PIPESTATUS[0]}"
expect_stopped "2>&1 | head" "$TMP/pipe2.jsonl" 2

# --- Ctrl-Z: SIGTSTP stops the cars, then the process
state_of() { sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | cut -d' ' -f1; }
# await_state PID STATE: until the process is in STATE (T: stopped), at most 20 s
await_state() {
  local deadline=$((SECONDS + 20))
  until [ "$(state_of "$1")" = "$2" ]; do
    [ $SECONDS -ge $deadline ] && return 1
    sleep 0.02
  done
}
rm -f "$TMP/tstp.fifo"
mkfifo "$TMP/tstp.fifo"
MODE=none $PITWALL run "$NAGGING" --cars 2 --record "$TMP/tstp.jsonl" >"$TMP/tstp.fifo" \
  2>"$TMP/tstp.err" &
RUN_PID=$!
exec 4<"$TMP/tstp.fifo"
read -r -t 20 -u 4 line
check "Ctrl-Z: the script is driving" "driving" "$line"
cat <&4 >/dev/null 2>&1 &
kill -TSTP $RUN_PID
await_state $RUN_PID T
check "Ctrl-Z: the process is suspended" T "$(state_of $RUN_PID)"
expect_stopped "Ctrl-Z: before the process stopped" "$TMP/tstp.jsonl" 2
contains "Ctrl-Z: the log says the cars are stopped" "suspended (Ctrl-Z): the cars are stopped" \
  "$(cat "$TMP/tstp.err")"
kill -CONT $RUN_PID
# fg resumes the engine: the script commands the cars again (set-speed 800 reaches both)
resumed() { [ "$(last_tx_per_car "$TMP/tstp.jsonl")" = $'1 set-speed 800\n2 set-speed 800' ]; }
deadline=$((SECONDS + 20))
until resumed || [ $SECONDS -ge $deadline ]; do sleep 0.05; done
resumed
check "Ctrl-Z, then fg: the engine runs again and the script commands the cars" 0 $?
kill -INT $RUN_PID
wait_bounded $RUN_PID
check "Ctrl-Z, fg, Ctrl-C: exit status" 130 $?
exec 4<&-
expect_stopped "Ctrl-Z, fg, Ctrl-C" "$TMP/tstp.jsonl" 2

# --- a refused start leaves the old record as it was
MODE=none $PITWALL run "$NAGGING" --fast --duration 2 --cars 2 --record "$TMP/old.jsonl" \
  >/dev/null 2>&1
check "the first race: exit status" 0 $?
cp "$TMP/old.jsonl" "$TMP/old.orig"
# a port in use: a listener of our own holds it
python3 -c '
import socket, time
s = socket.socket(); s.bind(("127.0.0.1", 0)); s.listen()
print(s.getsockname()[1], flush=True)
time.sleep(600)' >"$TMP/port" 2>/dev/null &
HOLD_PID=$!
wait_for "$TMP/port" '^[0-9]+$'
port=$(cat "$TMP/port")
refused() {  # NAME STATUS OPTION…: the run is refused with STATUS and the record is untouched
  local name=$1 status=$2
  shift 2
  MODE=none $PITWALL run "$NAGGING" --cars 2 --record "$TMP/old.jsonl" --duration 1 "$@" \
    </dev/null >"$TMP/refused.out" 2>"$TMP/refused.err"
  check "$name: refused with status $status" "$status" $?
  cmp -s "$TMP/old.jsonl" "$TMP/old.orig"
  check "$name: the old record is byte for byte as it was" 0 $?
}
refused "the view's port in use" 2 --view="127.0.0.1:$port"
contains "the view's port in use: says so" "$port" "$(cat "$TMP/refused.err")"
refused "a bad --view" 2 --view=nonsense
refused "--keyboard without a terminal" 2 --humans 1 --keyboard
PITWALL_INPUT_DIR="$TMP/no-such-folder" refused "--gamepads on a folder that is not there" 2 \
  --humans 1 --gamepads
kill $HOLD_PID 2>/dev/null
wait $HOLD_PID 2>/dev/null

finish
