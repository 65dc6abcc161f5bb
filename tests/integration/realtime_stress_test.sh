# Real-time grand prix races starved of CPU (docs/testing.md "Real-time stress"): a run in a cpu
# cgroup with a small quota, beside one with the machine as it is, each over several seeds, with
# the simulator's frames as late as a BLE connection makes them (the default in real time). Every
# car finishes; no car's laps average more than 1.5 times its best (no jam, no car left crawling);
# the engine says it fell behind real time in the starved runs, and never in the others.
#
# The cgroup is made here and removed at the end: cgroup v2 (cpu.max) or v1 (cpu.cfs_quota_us).
# Where neither can be made (not root, no cgroup file system) the test fails saying so: it is
# never skipped (CI runs as root, where it can always run). STRESS_QUOTA (percent of one CPU, default 1), STRESS_SEEDS
# (default "1 2") and LAPS (default 2) change it.
source "$(dirname "$0")/lib.sh"
QUOTA=${STRESS_QUOTA:-1}
SEEDS=${STRESS_SEEDS:-1 2}
LAPS=${LAPS:-2}

group=""
kind=""
if [ -d /sys/fs/cgroup/cpu ] && [ ! -f /sys/fs/cgroup/cgroup.controllers ]; then
  group=/sys/fs/cgroup/cpu/pitwall-stress-$$
  mkdir "$group" 2>/dev/null && kind=v1 || group=""
else
  here=$(sed -n 's/^0:://p' /proc/self/cgroup 2>/dev/null)
  group=/sys/fs/cgroup${here%/}/pitwall-stress-$$
  if mkdir "$group" 2>/dev/null && [ -w "$group/cpu.max" ]; then kind=v2; else
    rmdir "$group" 2>/dev/null
    group=""
  fi
fi
if [ -z "$kind" ]; then
  echo "FAIL: no cpu cgroup can be made here to starve the races in: run as root, with a cgroup"
  echo "file system (cgroup v1 cpu or v2 cpu.max), or leave this test out: ctest -E realtime_stress"
  exit 1
fi
trap 'rmdir "$group" 2>/dev/null; rm -rf "$TMP"' EXIT
if [ "$kind" = v1 ]; then
  echo 100000 >"$group/cpu.cfs_period_us"
  echo $((QUOTA * 1000)) >"$group/cpu.cfs_quota_us"
else
  echo "$((QUOTA * 1000)) 100000" >"$group/cpu.max"
fi
echo "ok: a cgroup $kind with a quota of $QUOTA % of a CPU"

# race NAME SEED [starved]: a real-time grand prix, its results and its stderr in $TMP/NAME.*
race() {
  local prefix=()
  [ "${3:-}" = starved ] && prefix=(bash -c 'echo $$ >"$0/cgroup.procs" && exec "$@"' "$group")
  LAPS=$LAPS "${prefix[@]}" $PITWALL run "$SRC/examples/grand_prix.lua" --seed "$2" \
    --results "$TMP/$1.json" >"$TMP/$1.out" 2>"$TMP/$1.err"
  echo $? >"$TMP/$1.rc"
}

# both at once: the starved run's quota leaves the machine to the other
for seed in $SEEDS; do
  race "starved-$seed" "$seed" starved &
  race "free-$seed" "$seed" &
  wait
done

for seed in $SEEDS; do
  for name in "starved-$seed" "free-$seed"; do
    check "$name: the run ends well" 0 "$(cat "$TMP/$name.rc")"
    verdict=$(python3 - "$TMP/$name.json" "$LAPS" <<'PY'
import json, sys
rows, laps = json.load(open(sys.argv[1])), int(sys.argv[2])
bad = []
for r in rows:
    if not r.get("finished") or r.get("laps") != laps:
        bad.append(f"{r['car']} did not finish its {laps} laps ({r.get('laps')})")
    elif r["totalTime"] / r["laps"] > 1.5 * r["bestLap"]:
        bad.append(f"{r['car']} averaged {r['totalTime'] / r['laps']:.2f} s a lap, best {r['bestLap']:.2f}")
print("ok" if len(rows) == 4 and not bad else "; ".join(bad) or f"{len(rows)} rows")
PY
)
    check "$name: every car finishes, none averaging over 1.5x its best lap" ok "$verdict"
  done
  said=$(grep -c 'the engine is falling behind real time' "$TMP/starved-$seed.err")
  [ "$said" -ge 1 ] && echo "ok: starved-$seed: the engine says it falls behind real time ($said)" ||
    fail "starved-$seed: the engine never said it fell behind real time"
  check "free-$seed: and the run with the machine as it is does not" 0 \
    "$(grep -c 'the engine is falling behind real time' "$TMP/free-$seed.err")"
done
[ "$kind" = v1 ] && echo "ok: the starved runs were throttled $(grep nr_throttled "$group/cpu.stat")"

finish
