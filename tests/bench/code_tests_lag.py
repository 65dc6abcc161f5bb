#!/usr/bin/env python3
"""The live race while thirty students test (docs/performance.md "The code page's tests"): how late
the engine's loop runs while the code page's Tests run as children beside it.

    tests/bench/code_tests_lag.py PITWALL [STUDENTS] [SECONDS]

Starts `pitwall run tests/bench/code_lag.lua --code TMP --view 127.0.0.1:0 --cars STUDENTS` (30):
every car drives its desk's driver (the starter) in practice. After 10 s idle, each of STUDENTS
desks joins and presses Test at once, and again each time its answer comes (as far as the rate
limit lets it) for SECONDS (20); then 10 s more. Prints the loop's lateness in each phase
(code_lag.lua's lines), the tests answered and refused, and their answer times.
"""
import http.client
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

pitwall = sys.argv[1]
students = int(sys.argv[2]) if len(sys.argv) > 2 else 30
seconds = float(sys.argv[3]) if len(sys.argv) > 3 else 20
here = os.path.dirname(os.path.abspath(__file__))
tmp = tempfile.mkdtemp(prefix="pitwall-code-lag-")
proc = subprocess.Popen([pitwall, "run", os.path.join(here, "code_lag.lua"), "--code", tmp + "/lesson",
                         "--view", "127.0.0.1:0", "--cars", str(students), "--no-db"],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
err_lines = []
threading.Thread(target=lambda: err_lines.extend(proc.stderr), daemon=True).start()
port = teacher = None
deadline = time.time() + 30
while time.time() < deadline and not (port and teacher):
    time.sleep(0.1)
    text = "".join(err_lines)
    m = re.search(r"view: http://127\.0\.0\.1:(\d+)/", text)
    t = re.search(r"#teacher=([0-9a-f]{32})", text)
    port, teacher = (m and int(m.group(1))), (t and t.group(1))
assert port and teacher, "".join(err_lines)[-2000:]


def request(method, path, body=None, token=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
    h = {"Content-Type": "application/json"}
    if token:
        h["Authorization"] = "Bearer " + token
    c.request(method, path, body=json.dumps(body) if body is not None else None, headers=h)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, json.loads(data or b"{}")


tokens = [request("POST", "/api/code/join", {"car": k + 1, "name": f"s{k + 1}"})[1]["token"]
          for k in range(students)]
starter = open(os.path.join(tmp, "lesson", "car-1", "driver.lua")).read()
time.sleep(10)
request("POST", "/api/code/teacher", {"action": "start", "laps": 1}, teacher)  # phase: tests
answered, refused, times = [], [], []
end = time.time() + seconds


def student(token):
    while time.time() < end:
        t0 = time.time()
        status, j = request("POST", "/api/code/test", {"text": starter}, token)
        if status == 200:
            answered.append(j.get("status"))
            times.append((time.time() - t0, j.get("seconds", 0), j.get("waited", 0)))
        else:
            refused.append(status)
            time.sleep(1)


threads = [threading.Thread(target=student, args=(t,)) for t in tokens]
for t in threads:
    t.start()
for t in threads:
    t.join()
request("POST", "/api/code/teacher", {"action": "start", "laps": 1}, teacher)  # phase: after
time.sleep(10)
request("POST", "/api/code/teacher", {"action": "start", "laps": 1}, teacher)  # the end
out, _ = proc.communicate(timeout=60)
for line in out.splitlines():
    if line.startswith("lag "):
        print(line)
times.sort()
q = lambda v, p: v[min(len(v) - 1, int(p * len(v)))] if v else 0
print(f"tests: {len(answered)} answered ({answered.count('finished')} finished), {len(refused)} "
      f"refused ({sorted(set(refused))}) by {students} students in {seconds:.0f} s")
print(f"answer time: p50 {q([t[0] for t in times], 0.5):.2f} s, max {times[-1][0] if times else 0:.2f} s; "
      f"a test's own run: p50 {q(sorted(t[1] for t in times), 0.5):.3f} s; "
      f"queued: p50 {q(sorted(t[2] for t in times), 0.5):.2f} s, max {max((t[2] for t in times), default=0):.2f} s")
subprocess.run(["rm", "-rf", tmp])
