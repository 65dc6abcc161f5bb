#!/usr/bin/env python3
"""What reading a record's laps costs (docs/performance.md "Ghosts"): sim.addGhost reads its
record in the call, within the script's budget, so its largest record (512 KB) must read in a
fraction of the budget; `pitwall compare` reads records as `pitwall replay` does, plus the traces.

Usage: tests/bench/ghost_read.py PITWALL [RUNS]. Makes a four-car record of just under 512 KB
(--sensor ideal: every code reported), then, RUNS times each (default 7): the CPU time of
sim.addGhost on it (os.clock around the call), and the wall time of `pitwall replay --json` (the
floor: the same playback) and of `pitwall compare` of two of its laps. Prints medians and ratios.
"""
import os, statistics, subprocess, sys, tempfile, time

pitwall = os.path.abspath(sys.argv[1])
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 7
work = tempfile.mkdtemp()
os.chdir(work)
with open("four.lua", "w") as f:
    f.write("for i, car in ipairs(pitwall.cars()) do car:setSpeed(700 + 100 * i, 20000) end\n"
            "pitwall.spawn(function() pitwall.sleep(SECONDS) pitwall.stop() end)\n")
seconds = 46
while True:
    text = open("four.lua").read().replace("SECONDS", str(seconds))
    open("run.lua", "w").write(text)
    subprocess.run([pitwall, "run", "run.lua", "--fast", "--sensor", "ideal", "--record", "rec.jsonl",
                    "-q"], check=True, stderr=subprocess.DEVNULL)
    size = os.path.getsize("rec.jsonl")
    if size <= 512 * 1024:
        break
    seconds -= 2
with open("ghost.lua", "w") as f:
    f.write('local sim = require "pitwall.sim"\nlocal t0 = os.clock()\n'
            'sim.addGhost { record = "rec.jsonl" }\n'
            'print(string.format("%.6f", os.clock() - t0))\npitwall.stop()\n')

def wall(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0

ghost, replay, compare = [], [], []
for _ in range(runs):
    out = subprocess.run([pitwall, "run", "ghost.lua", "--fast", "-q"], check=True,
                         capture_output=True, text=True).stdout
    ghost.append(float(out.split()[-1]))
    replay.append(wall([pitwall, "replay", "rec.jsonl", "--json"]))
    compare.append(wall([pitwall, "compare", "rec.jsonl:1", "rec.jsonl:2"]))
g, r, c = (statistics.median(x) for x in (ghost, replay, compare))
print(f"record: {size} bytes, {sum(1 for _ in open('rec.jsonl'))} lines, {seconds} s of four cars")
print(f"sim.addGhost: {g * 1000:.1f} ms of CPU (median of {runs}; max {max(ghost) * 1000:.1f} ms), "
      f"{size / g / 1e6:.1f} MB/s")
print(f"pitwall replay --json (floor): {r * 1000:.0f} ms wall; pitwall compare of two laps: "
      f"{c * 1000:.0f} ms wall: {c / r:.2f}x the floor")
