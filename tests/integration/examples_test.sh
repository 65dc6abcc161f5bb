# Every example runs to its end on the simulator without a script error (docs stay true).
source "$(dirname "$0")/lib.sh"
for script in "$SRC"/examples/*.lua; do
  name=$(basename "$script")
  err=$(LAPS=2 $PITWALL run "$script" --fast --cars 2 --duration 120 2>&1 >"$TMP/out"); rc=$?
  check "$name exit status" 0 "$rc"
  case "$err" in *"error "*) fail "$name reported an error: $err" ;; *) echo "ok: $name ran cleanly" ;; esac
  [ -s "$TMP/out" ] && echo "ok: $name printed something" || fail "$name printed nothing"
done

# The tutorial (docs/tutorial.md): its scripts run to their end the same way, and its scenario
# test passes in virtual time from the top folder, as the tutorial runs it — and fails, naming
# why, when the car takes the curves too fast (the tutorial's "try it").
for script in "$SRC"/examples/tutorial/*.lua; do
  case "$script" in *_test.lua) continue ;; esac
  name=tutorial/$(basename "$script")
  err=$(LAPS=2 $PITWALL run "$script" --fast --cars 2 --duration 120 2>&1 >"$TMP/out"); rc=$?
  check "$name exit status" 0 "$rc"
  case "$err" in *"error "*) fail "$name reported an error: $err" ;; *) echo "ok: $name ran cleanly" ;; esac
  [ -s "$TMP/out" ] && echo "ok: $name printed something" || fail "$name printed nothing"
done
out=$(cd "$SRC" && env -u LAPS -u FAST -u SLOW "$PITWALL" test examples/tutorial 2>&1); rc=$?
check "the tutorial's test passes" 0 "$rc"
contains "the tutorial's test ran" "1 passed, 0 failed" "$out"
out=$(cd "$SRC" && env -u LAPS -u FAST SLOW=1400 "$PITWALL" test examples/tutorial 2>&1); rc=$?
check "the tutorial's test fails with SLOW=1400" 1 "$rc"
contains "it says the car came off the track" "off the track: expected false or nil, got true" "$out"
# Every Lua listing in docs/tutorial.md is the script it names, or a part of it, word for word.
out=$(python3 - "$SRC" <<'PY'
import glob, re, sys
src = sys.argv[1]
scripts = [open(f).read() for f in glob.glob(src + "/examples/tutorial/*.lua")]
blocks = re.findall(r"```lua\n(.*?)```", open(src + "/docs/tutorial.md").read(), re.S)
print(len(blocks), "listings")
for b in blocks:
    if not any(b in s for s in scripts):
        print("not in examples/tutorial:", b.splitlines()[0])
PY
)
check "docs/tutorial.md's listings are the scripts" "5 listings" "$out"

out=$(LAPS=2 $PITWALL run "$SRC/examples/lap_times.lua" --fast --cars 4 2>/dev/null)
check "lap_times prints 2 laps for each of 4 cars" 8 "$(echo "$out" | grep -c ' lap [0-9]')"

# The classroom's race, run without --code: a sentence saying how to run it, exit status 1.
err=$($PITWALL run "$SRC/examples/classroom/race.lua" --fast 2>&1 >/dev/null); rc=$?
check "classroom/race.lua without --code: exit status" 1 "$rc"
contains "classroom/race.lua without --code: says how to run it" \
  "classroom/race.lua is the code page's race: run it with --code FOLDER" "$err"
finish
