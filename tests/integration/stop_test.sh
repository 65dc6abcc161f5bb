# The stop is the last word (docs/safety.md), played against a script that never stops
# commanding: every 20 ms it sets every car's speed again. After each way a run ends the last frame
# each car got must be its stop (set-speed 0), and the exit status must say how the run ended.
source "$(dirname "$0")/lib.sh"

NAGGING="$SRC/tests/integration/nagging.lua"

# --duration (virtual time)
MODE=none $PITWALL run "$NAGGING" --fast --duration 5 --cars 3 --record "$TMP/d.jsonl" \
  >"$TMP/d.out" 2>"$TMP/d.err"
check "--duration: exit status" 0 $?
expect_stopped "--duration" "$TMP/d.jsonl" 3
# the script's hold on the library's last words: its command refused, its loop interrupted
contains "last words: the command refused" "last words:	false" "$(cat "$TMP/d.out")"
contains "last words: the loop interrupted" "error in the end of the run (pitwall._lastWords): " \
  "$(cat "$TMP/d.err")"
contains "last words: where it ran" "nagging.lua:32: still running after 100 ms" "$(cat "$TMP/d.err")"

# the --fast safety cap: no --duration, and the script never ends the run
MODE=none $PITWALL run "$NAGGING" --fast --fast-cap 5 --cars 3 --record "$TMP/c.jsonl" \
  >/dev/null 2>&1
check "--fast-cap: exit status" 124 $?
expect_stopped "--fast-cap" "$TMP/c.jsonl" 3

# pitwall.stop(), then commands from the same task, a pcall and a new task
out=$(MODE=stop $PITWALL run "$NAGGING" --fast --cars 3 --record "$TMP/s.jsonl" 2>&1)
check "pitwall.stop(): exit status" 0 $?
contains "pitwall.stop(): a command after it is refused" "after stop:	false" "$out"
contains "pitwall.stop(): the refusal says why" "takes no more commands" "$out"
expect_stopped "pitwall.stop()" "$TMP/s.jsonl" 3

# a main chunk that dies
out=$(MODE=error $PITWALL run "$NAGGING" --fast --cars 2 --record "$TMP/e.jsonl" 2>&1)
check "dying main chunk: exit status" 1 $?
contains "dying main chunk: the error is shown" "the strategy crashed" "$out"
expect_stopped "dying main chunk" "$TMP/e.jsonl" 2

# os.exit(3), even inside pcall, goes through the stop path with its status
MODE=exit $PITWALL run "$NAGGING" --fast --cars 2 --record "$TMP/x.jsonl" >/dev/null 2>&1
check "os.exit(3): exit status" 3 $?
expect_stopped "os.exit" "$TMP/x.jsonl" 2

# the memory cap: an allocation loop behind pcall, the callback budget off so that only the cap
# can end it; the process's peak memory stays near the cap.
out=$(MODE=memory python3 - "$PITWALL" "$NAGGING" "$TMP/m.jsonl" <<'PY'
import resource, subprocess, sys
p = subprocess.run([sys.argv[1], "run", sys.argv[2], "--fast", "--cars", "2", "--budget", "0",
                    "--lua-memory", "64", "--record", sys.argv[3]], capture_output=True, text=True)
peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024
print("status", p.returncode)
print("bounded" if peak_mb < 64 + 100 else "peak %d MB" % peak_mb)
print(p.stderr)
PY
)
contains "memory cap: exit status 1" "status 1" "$out"
contains "memory cap: the process stays near the cap" "bounded" "$out"
contains "memory cap: the error says what and what to do" \
  "script memory limit of 64 MB reached (the script keeps too much" "$out"
expect_stopped "memory cap" "$TMP/m.jsonl" 2

# os.exit at the REPL's prompt (piped input): the cars are stopped and the status is os.exit's
out=$(printf 'cars[1]:setSpeed(800)\nos.exit(4)\nprint("still here")\n' |
  $PITWALL repl --cars 1 2>&1)
check "os.exit at the REPL: exit status" 4 $?
case "$out" in
  *"still here"*) fail "os.exit at the REPL: a line after it ran" ;;
  *) echo "ok: os.exit at the REPL: nothing after it ran" ;;
esac

# SIGINT and SIGTERM in real time: 130, cars stopped; two SIGINTs at once leave at once, and
# still stop the cars.
for sig in INT TERM INT2; do
  mkfifo "$TMP/out.$sig"
  MODE=none $PITWALL run "$NAGGING" --cars 2 --record "$TMP/$sig.jsonl" \
    >"$TMP/out.$sig" 2>/dev/null &
  pid=$!
  exec 3<"$TMP/out.$sig"
  read -r -t 20 line <&3
  check "SIG$sig: the run is driving" "driving" "$line"
  if [ $sig = INT2 ]; then
    kill -INT $pid
    kill -INT $pid
  else
    kill -$sig $pid
  fi
  wait $pid
  check "SIG$sig: exit status" 130 $?
  exec 3<&-
  expect_stopped "SIG$sig" "$TMP/$sig.jsonl" 2
done

# SIGINT while the world is being made (its Lua library still loading, here a library that takes
# 5 s of CPU to load): an exit of 130 with the cars stopped, and no error of the library's
# (clean clone run 19 saw `pitwall run` exit 1 when a Ctrl-C came that early).
cp -r "$SRC/scripts" "$TMP/slowlib"
{
  echo 'print("loading the library")'
  echo 'local t = os.clock(); while os.clock() - t < 5 do end'
  cat "$SRC/scripts/pitwall/core.lua"
} >"$TMP/slowlib/pitwall/core.lua"
RUN_FIFO_SAYS="loading the library" run_fifo slow env PITWALL_SCRIPTS="$TMP/slowlib" MODE=none \
  $PITWALL run "$NAGGING" --cars 2 --budget 0 --record "$TMP/slow.jsonl"
kill -INT $RUN_PID
wait_bounded $RUN_PID
check "SIGINT while the library loads: exit status" 130 $?
exec 4<&-
expect_stopped "SIGINT while the library loads" "$TMP/slow.jsonl" 2
if grep -q "cannot load" "$TMP/slow.err"; then
  fail "SIGINT while the library loads: no error of the library's: $(cat "$TMP/slow.err")"
else
  echo "ok: SIGINT while the library loads: no error of the library's"
fi

# The same in a --fast run, which never sleeps: the signal reaches it through the loop's pass
# check (Loop::setPassCheck), not through a read kept pending on the loop. Without the signal the
# run would go on for 24 simulated hours (--fast-cap), minutes of wall time.
for sig in INT TERM; do
  mkfifo "$TMP/fast.$sig"
  MODE=none $PITWALL run "$NAGGING" --fast --cars 2 --record "$TMP/fast.$sig.jsonl" \
    >"$TMP/fast.$sig" 2>/dev/null &
  pid=$!
  exec 3<"$TMP/fast.$sig"
  read -r -t 20 line <&3
  check "--fast, SIG$sig: the run is driving" "driving" "$line"
  kill -$sig $pid
  wait_bounded $pid
  check "--fast, SIG$sig: exit status" 130 $?
  exec 3<&-
  expect_stopped "--fast, SIG$sig" "$TMP/fast.$sig.jsonl" 2
done

# A periodic callback slower than its period (50 ms every 10 ms) does not hold up one-shot timers
# nor Ctrl-C; and with the callback budget off, neither does one that never returns.
cat > "$TMP/hog.lua" <<'LUA'
local spin = os.getenv("SPIN") == "forever"
for _, car in ipairs(pitwall.cars()) do car:setSpeed(600) end
local said = false
pitwall.every(0.01, function()
  if spin and not said then
    said = true
    print("hogging")
    io.stdout:flush()
  end
  local t = pitwall.now()  -- the real clock: 50 ms of wall time, however loaded the machine
  while spin or pitwall.now() - t < 0.05 do end
end)
pitwall.after(1.0, function() print(string.format("after %.3f", pitwall.now())) end)
pitwall.after(1.5, function() print("driving"); io.stdout:flush() end)
LUA
for spin in slow forever; do
  budget=0.1
  [ $spin = forever ] && budget=0
  mkfifo "$TMP/hog.$spin"
  SPIN=$spin $PITWALL run "$TMP/hog.lua" --cars 2 --budget $budget --record "$TMP/hog.$spin.jsonl" \
    >"$TMP/hog.$spin" 2>"$TMP/hog.$spin.err" &
  pid=$!
  exec 3<"$TMP/hog.$spin"
  if [ $spin = slow ]; then
    read -r -t 20 line <&3
    t=${line#after }
    python3 -c "import sys; sys.exit(0 if 1.0 <= float('$t') <= 1.1 else 1)" 2>/dev/null &&
      echo "ok: after(1.0) fires on time beside a hog ($line)" ||
      fail "after(1.0) beside a hog fired at [$line]"
    read -r -t 20 line <&3
  else
    read -r -t 20 line <&3
    check "a callback that never returns is running" "hogging" "$line"
  fi
  begin=$EPOCHREALTIME
  kill -INT $pid
  wait $pid
  rc=$?
  took=$(python3 -c "print(round($EPOCHREALTIME - $begin, 3))")
  exec 3<&-
  check "Ctrl-C beside a $spin hog: exit status" 130 $rc
  python3 -c "import sys; sys.exit(0 if $took < 1.0 else 1)" &&
    echo "ok: Ctrl-C beside a $spin hog ends the run in $took s" ||
    fail "Ctrl-C beside a $spin hog took $took s"
  expect_stopped "Ctrl-C beside a $spin hog" "$TMP/hog.$spin.jsonl" 2
done

# --fast beside a callback that never returns (budget off): the handler interrupts the Lua code
# and the virtual loop, which never sleeps, acts on the signal on its next pass.
mkfifo "$TMP/hog.fast"
SPIN=forever $PITWALL run "$TMP/hog.lua" --fast --cars 2 --budget 0 --record "$TMP/hog.fast.jsonl" \
  >"$TMP/hog.fast" 2>"$TMP/hog.fast.err" &
pid=$!
exec 3<"$TMP/hog.fast"
read -r -t 20 line <&3
check "--fast: a callback that never returns is running" "hogging" "$line"
kill -INT $pid
wait_bounded $pid
check "--fast: Ctrl-C beside a hog: exit status" 130 $?
exec 3<&-
expect_stopped "--fast: Ctrl-C beside a hog" "$TMP/hog.fast.jsonl" 2

finish
