# Engine-side copies count against the script (docs/safety.md, issue 33 finding 6): under
# --lua-memory 64, a race table holding one 1 MiB string 1500 times once took the process to
# 1.55 GB and held the loop ~8 s. It is refused with a sentence naming the limit, in bounded
# memory, and the run goes on to its own end (the stop path: every car's last frame its stop).
source "$(dirname "$0")/lib.sh"

cat >"$TMP/attack.lua" <<'LUA'
local big = string.rep("x", 1 << 20)
local rows = {}
for i = 1, 1500 do rows[i] = { car = big } end
local ok, err = pcall(pitwall.view.race, { rows = rows })
print("race table:", ok, err)
pitwall.view.race { title = "after" }
pitwall.after(0.5, function() pitwall.stop() end)
LUA

# The child's peak resident memory in MB (ru_maxrss of the one child run), and its status.
python3 - "$PITWALL" "$TMP/attack.lua" "$TMP/a.jsonl" >"$TMP/a.out" 2>"$TMP/a.err" <<'PY'
import resource, subprocess, sys
r = subprocess.run([sys.argv[1], "run", sys.argv[2], "--view", "0", "--lua-memory", "64",
                    "--cars", "2", "--record", sys.argv[3]], capture_output=True, text=True)
print(r.stdout, end="")
sys.stderr.write(r.stderr)
print("status", r.returncode)
print("peak MB", resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss // 1024)
PY
out=$(cat "$TMP/a.out")
contains "the copy is refused with a sentence naming the limit" \
  "race table:	false	" "$out"
contains "... which limit" "pitwall.view.race: the data is more than 8 MiB" "$out"
check "the run ends as the script asked" "status 0" "$(grep '^status' "$TMP/a.out")"
peak=$(sed -n 's/^peak MB //p' "$TMP/a.out")
if [ "${peak:-9999}" -lt 200 ]; then echo "ok: peak memory ${peak} MB (under 200 MB)"; else
  fail "peak memory ${peak} MB, expected under 200 MB"; fi
expect_stopped "the end of the run" "$TMP/a.jsonl" 2

finish
