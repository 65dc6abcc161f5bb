#!/usr/bin/env python3
"""Hostile requests to the code page (docs/classroom.md "Safe by design"), against a run of
`pitwall run --code FOLDER --view 127.0.0.1:0 --view-host classroom.test --cars 3` (the join code
needed) whose desks 1 and 2 other students hold.

    code_hostile.py PORT JOIN-CODE TEACHER-KEY FOLDER

Mallory joins desk 3 and tries to reach the others: another desk's number in the body, paths that
climb out of the history, other credentials, the teacher's actions; then oversized, malformed and
rapid requests. Desks 1 and 2 must end byte for byte as they were, nothing may be written outside
FOLDER/car-3, every refusal must be a status with a sentence, and the view must answer throughout.
Last (it locks this address out): wrong join codes. PASS/FAIL lines; exit status 1 on a failure.
"""
import http.client
import json
import os
import sys

port, code, teacher, folder = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
failures = 0


def check(name, ok, detail=""):
    global failures
    print(("PASS: " if ok else "FAIL: ") + name + ("" if ok else f": {detail}"))
    if not ok:
        failures += 1


def request(method, path, body=None, token=None, headers=None, raw=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    h = {"Host": f"127.0.0.1:{port}"}
    if token is not None:
        h["Authorization"] = "Bearer " + token
    data = raw if raw is not None else (json.dumps(body).encode() if body is not None else None)
    if data is not None:
        h["Content-Type"] = "application/json"
    h.update(headers or {})
    c.request(method, path, body=data, headers=h)
    r = c.getresponse()
    text = r.read()
    c.close()
    try:
        parsed = json.loads(text)
    except ValueError:
        parsed = None
    return r.status, parsed, text


def snapshot(desk):
    out = {}
    base = os.path.join(folder, f"car-{desk}")
    for root, _, files in os.walk(base):
        for f in files:
            p = os.path.join(root, f)
            out[os.path.relpath(p, base)] = open(p, "rb").read()
    return out


def everything():
    out = set()
    for root, dirs, files in os.walk(os.path.dirname(folder)):
        for f in files + dirs:
            out.add(os.path.join(root, f))
    return out


def sentence(name, status, parsed, want):
    check(f"{name}: {want}", status == want and isinstance(parsed, dict) and
          isinstance(parsed.get("error"), str) and len(parsed["error"]) > 10,
          f"HTTP {status} {parsed}")


before = {1: snapshot(1), 2: snapshot(2)}
outside = everything()

status, j, _ = request("POST", "/api/code/join", {"code": code, "car": 3, "name": "Mallory"})
check("Mallory joins desk 3 with the join code", status == 200 and j and len(j["token"]) == 32,
      f"HTTP {status} {j}")
m = j["token"]

# another desk's number in the body: the credential says which desk, nothing else
status, j, _ = request("POST", "/api/code/save", {"text": "-- mallory\n", "car": 1, "desk": 2},
                       token=m)
check("a save naming desk 1 in its body saves to Mallory's own desk",
      status == 200 and open(os.path.join(folder, "car-3", "driver.lua")).read() == "-- mallory\n",
      f"HTTP {status} {j}")
status, j, _ = request("GET", "/api/code/me?car=1", token=m)
check("/me?car=1 is still Mallory's desk", status == 200 and j["car"] == 3, f"HTTP {status} {j}")

# paths that climb out of the history, numbers that are none
for path in ["/api/code/history/../../car-1/driver.lua", "/api/code/history/..%2f..%2fcar-1%2fdriver.lua",
             "/api/code/history/1/../../../../etc/passwd", "/api/code/history/%2e%2e",
             "/api/code/history/-1", "/api/code/history/0", "/api/code/history/99999999999999999999",
             "/api/code/history/1.lua", "/api/code/history/0x1", "/api/code/history/", "/api/code/../../etc/passwd",
             "/api/code/history/1%00"]:
    status, j, text = request("GET", path, token=m)
    check(f"GET {path}: refused with a sentence, nothing read", status in (400, 404) and
          b"root:" not in text and b"mallory" not in text and isinstance(j, dict) and "error" in j,
          f"HTTP {status} {text[:200]!r}")
status, j, text = request("GET", "/api/code/history/1", token=m)
check("Mallory's own save 1 is hers", status == 200 and text == b"-- mallory\n", f"HTTP {status} {text[:80]!r}")

# other credentials: none, garbage, long, the teacher's key as a desk's, another scheme
for name, tok, hdr in [("no credential", None, None), ("an empty one", "", None),
                       ("a guessed one", "0" * 32, None), ("a 10 kB one", "a" * 10000, None),
                       ("the teacher's key", teacher, None),
                       ("lower-case bearer", None, {"Authorization": "bearer " + m}),
                       ("Basic", None, {"Authorization": "Basic " + m})]:
    status, j, _ = request("GET", "/api/code/me", token=tok, headers=hdr)
    sentence(f"/me with {name}", status, j, 401)
    status, j, _ = request("POST", "/api/code/save", {"text": "-- x\n"}, token=tok, headers=hdr)
    sentence(f"a save with {name}", status, j, 401)
status, j, _ = request("POST", "/api/code/teacher", {"action": "lock"}, token=m)
sentence("a student's credential on the teacher's actions", status, j, 403)
status, j, _ = request("GET", "/api/code/teacher", token=m)
sentence("a student's credential on the teacher's list", status, j, 403)

# oversized, malformed
status, j, _ = request("POST", "/api/code/save", {"text": "-" * (32 * 1024 + 1)}, token=m)
sentence("a 32 KiB + 1 file", status, j, 413)
status, _, text = request("POST", "/api/code/save", raw=b'{"text":"' + b"a" * (300 * 1024) + b'"}', token=m)
check("a 300 KiB body is refused (413) with a sentence", status == 413 and b"256 KiB" in text,
      f"HTTP {status} {text[:120]!r}")
for name, raw in [("not JSON", b"text=1"), ("a JSON array", b"[1,2]"), ("deep nesting", b"[" * 100000),
                  ("invalid UTF-8", b'{"text":"\xff\xfe\xc3"}'), ("the text a number", b'{"text":12}'),
                  ("the text null", b'{"text":null}'), ("empty", b"")]:
    status, j, _ = request("POST", "/api/code/save", raw=raw, token=m)
    sentence(f"a save of {name}", status, j, 400)
for name, body in [("car 1e300", {"code": code, "car": 1e300, "name": "x"}),
                   ("car -1", {"code": code, "car": -1, "name": "x"}),
                   ("car 2^63", {"code": code, "car": 2**63, "name": "x"}),
                   ("car \"3\"", {"code": code, "car": "3", "name": "x"}),
                   ("a 10k name", {"code": code, "car": 3, "name": "x" * 10000})]:
    status, j, _ = request("POST", "/api/code/join", body)
    check(f"join with {name}: refused with a sentence", status in (400, 404, 409) and "error" in (j or {}),
          f"HTTP {status} {j}")
status, j, _ = request("POST", "/api/code/join", {"code": code, "car": 1, "name": "Mallory"})
sentence("taking desk 1, which Alice holds", status, j, 409)

# another site's page, or a name rebound to this machine: refused before the code page
status, _, _ = request("POST", "/api/code/save", {"text": "-- x\n"}, token=m,
                       headers={"Origin": "http://evil.example"})
check("a save from another site's page (Origin) is refused", status == 403, f"HTTP {status}")
status, _, _ = request("POST", "/api/code/save", {"text": "-- x\n"}, token=m,
                       headers={"Host": f"evil.example:{port}"})
check("a save by a rebound name (Host) is refused", status == 403, f"HTTP {status}")

# rapid saves: the burst, then refused; nothing lost of what was saved
codes = [request("POST", "/api/code/save", {"text": f"-- rapid {k}\n"}, token=m)[0] for k in range(40)]
check("40 rapid saves: at most the burst of 10 taken, the rest 429", codes.count(200) <= 10 and
      codes.count(429) >= 30 and set(codes) <= {200, 429}, str(codes))
status, j, _ = request("GET", "/api/code/history", token=m)
kept = [s["version"] for s in j["saves"]]
check("every save taken is in the history", len(kept) == 1 + codes.count(200), str(kept))

# a test: what it runs is the page's text; a file that returns no driver is said (one test at a
# time per desk and the queue are tests/unit/view/code_api_test.cpp's, with a child that waits)
status, j, _ = request("POST", "/api/code/test", {"text": "return 1\n"}, token=m)
check("a test of a file that returns no driver says so", status == 200 and
      "must return a driver" in (j or {}).get("reason", ""), f"HTTP {status} {str(j)[:300]}")

# a flood of reads: answered, the view alive
statuses = {request("GET", "/api/code/me", token=m)[0] for _ in range(300)}
check("300 reads in a row are answered", statuses == {200}, str(statuses))

check("desks 1 and 2 are byte for byte as they were", snapshot(1) == before[1] and snapshot(2) == before[2],
      "changed")
new = {p for p in everything() - outside if "/car-3/" not in p}
check("nothing was written outside Mallory's desk folder", not new, str(sorted(new)[:10]))

# one desk a device: students behind the --view-host proxy (X-Forwarded-For names them)
def proxied(ip):
    return {"Host": f"classroom.test:{port}", "X-Forwarded-For": ip}


status, _, _ = request("POST", "/api/code/teacher", {"action": "free", "car": 3}, token=teacher)
check("the teacher frees Mallory's desk", status == 200, f"HTTP {status}")
status, j, _ = request("POST", "/api/code/join", {"code": code, "car": 3, "name": "Eve"},
                       headers=proxied("10.9.0.5"))
check("a student behind the proxy takes desk 3", status == 200, f"HTTP {status} {j}")
status, _, _ = request("POST", "/api/code/teacher", {"action": "free", "car": 2}, token=teacher)
status, j, _ = request("POST", "/api/code/join", {"code": code, "car": 2, "name": "Eve again"},
                       headers=proxied("10.9.0.5"))
check("the same device cannot take a second desk (409, with a sentence)",
      status == 409 and "holds car 3 already" in (j or {}).get("error", ""), f"HTTP {status} {j}")
status, j, _ = request("POST", "/api/code/join", {"code": code, "car": 2, "name": "Frank"},
                       headers=proxied("10.9.0.6"))
check("another device takes it", status == 200, f"HTTP {status} {j}")

# last: wrong join codes are counted per address and locked out
said = []
for k in range(7):
    status, j, _ = request("POST", "/api/code/join", {"code": "000000" if code != "000000" else "111111",
                                                        "car": 3, "name": "x"})
    said.append((status, (j or {}).get("error", "")))
check("wrong join codes are refused (403)", all(s == 403 for s, _ in said), str(said))
check("and locked out after 5", any("locked out" in e or "try again" in e for _, e in said[5:]), str(said[-2:]))
status, _, _ = request("GET", "/api/state")
check("the view answers after all of it", status == 200, f"HTTP {status}")
print("code_hostile: all passed" if failures == 0 else f"code_hostile: {failures} check(s) failed")
sys.exit(1 if failures else 0)
