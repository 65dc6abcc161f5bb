# The record is never lost (docs/safety.md): a run killed with SIGKILL leaves a --record file
# whose every line parses and which reaches within 100 ms of the kill. The script commands its
# cars every 20 ms, so frames keep coming; at 1.5 s of engine time it writes that time to a
# marker file, and the test kills pitwall the moment the marker appears.
source "$(dirname "$0")/lib.sh"

cat > "$TMP/kill.lua" <<'LUA'
local cars = pitwall.cars()
pitwall.every(0.02, function()
  for _, car in ipairs(cars) do car:setSpeed(700) end
end)
pitwall.after(1.5, function()
  local f = assert(io.open(os.getenv("MARK") .. ".tmp", "w"))
  f:write(string.format("%.6f\n", pitwall.now()))
  f:close()
  os.rename(os.getenv("MARK") .. ".tmp", os.getenv("MARK"))  -- appears whole
end)
LUA

out=$(MARK="$TMP/mark" python3 - "$PITWALL" "$TMP/kill.lua" "$TMP/rec.jsonl" "$TMP/mark" <<'PY'
import json, os, signal, subprocess, sys, time
pitwall, script, record, mark = sys.argv[1:]
p = subprocess.Popen([pitwall, "run", script, "--cars", "2", "--record", record],
                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
deadline = time.monotonic() + 30
while not os.path.exists(mark):
    if time.monotonic() > deadline or p.poll() is not None:
        print("no marker"); sys.exit(0)
    time.sleep(0.005)
p.send_signal(signal.SIGKILL)
p.wait()
marked = float(open(mark).read())
times = []
bad = 0
for line in open(record):
    try:
        times.append(json.loads(line)["t"])
    except Exception:
        bad += 1
print("killed", p.returncode == -signal.SIGKILL)
print("lines", len(times), "unparsable", bad)
print("lost %.3f s" % (marked - max(times)) if times else "empty")
print("within 100 ms" if times and max(times) >= marked - 0.1 else "more than 100 ms lost")
PY
)
echo "$out"
contains "pitwall was killed with SIGKILL" "killed True" "$out"
contains "every line of the record parses" "unparsable 0" "$out"
contains "the record reaches within 100 ms of the kill" "within 100 ms" "$out"

finish
