#!/usr/bin/env bash
# --view as a user runs it (docs/view.md): bound to 127.0.0.1 unless another address is given,
# a port in use or a bad form refused with a clear error before any car moves, /api/state's
# schema with every placed car on the drawn road, /ws paced to 30 updates a second, a flood of
# connections past the file descriptor limit (no spin), and the view on `repl` and `bridge` too. Python (python3-websocket) plays the page's side.
source "$(dirname "$0")/lib.sh"
PIDS=()
cleanup() {
  exec 2>/dev/null
  for p in "${PIDS[@]}"; do kill -9 "$p"; done
  wait
  rm -rf "$TMP"
}
trap cleanup EXIT

# start_view NAME ARGS…: runs pitwall ARGS… in the background, waits for its view URL; sets URL.
start_view() {
  local name=$1
  shift
  "$PITWALL" "$@" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  PIDS+=($!)
  if ! wait_for "$TMP/$name.err" '^view: http://' 20; then
    fail "$name: no view URL in 20 s"
    sed 's/^/  | /' "$TMP/$name.err"
    finish
  fi
  URL=$(grep -oE '^view: http://[^ ]+' "$TMP/$name.err" | head -1 | sed 's/^view: //')
}

# listening_on PORT: the local address the socket listening on PORT is bound to (IPv4).
listening_on() {
  python3 - "$1" <<'PY'
import sys
port = int(sys.argv[1])
for line in open("/proc/net/tcp").read().splitlines()[1:]:
    local, state = line.split()[1], line.split()[3]
    addr, p = local.split(":")
    if int(p, 16) == port and state == "0A":  # LISTEN
        print(".".join(str(int(addr[i:i + 2], 16)) for i in (6, 4, 2, 0)))
PY
}

# 1. The default address is loopback; the state is whole and every placed car is on the road.
start_view run run "$SRC/examples/grand_prix.lua" --view 0
port=${URL##*:}
port=${port%/}
contains "the URL is on 127.0.0.1" "http://127.0.0.1:" "$URL"
check "bound to 127.0.0.1 only" "127.0.0.1" "$(listening_on "$port")"
result=$(timeout 60 python3 - "$URL" <<'PY'
import json, math, sys, time, urllib.request
url = sys.argv[1]
def state():
    return json.load(urllib.request.urlopen(url + "api/state", timeout=5))

# The centre line, sampled from the pieces as docs/view.md defines them.
def centre(track):
    pts = []
    for p in track["pieces"]:
        x, y, h = p["x"], p["y"], math.radians(p["heading"])
        for k in range(51):
            f = k / 50
            if not p["turn"]:
                pts.append((x + math.cos(h) * p["length"] * f, y + math.sin(h) * p["length"] * f))
            else:
                t, r = p["turn"], p["radius"]
                cx, cy = x - t * math.sin(h) * r, y + t * math.cos(h) * r
                a = math.atan2(y - cy, x - cx) + t * f * math.pi / 2
                pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return pts

deadline = time.time() + 50
checked, placed_seen = 0, set()
while time.time() < deadline and len(placed_seen) < 4:
    s = state()
    assert s["type"] == "state" and s["version"] == 1 and s["source"] == "simulator", s["type"]
    for key in ("time", "track", "race", "replay", "cars", "events"):
        assert key in s, key
    t = s["track"]
    assert t["name"] == "oval" and t["source"] == "layout" and len(t["pieces"]) == 9
    line = centre(t)
    # the centre line closes: the end of the last piece is the start of the first
    assert math.dist(line[-1], line[0]) < 0.5, (line[-1], line[0])
    b = t["bounds"]
    for c in s["cars"]:
        for key in ("number", "name", "color", "connected", "onTrack", "delocalized", "piece",
                    "pieceIndex", "location", "fraction", "offset", "speed", "lap", "lapTimes",
                    "x", "y", "heading", "speedHistory", "framesIn"):
            assert key in c, key
        if c["x"] is None:
            continue
        assert b["minX"] <= c["x"] <= b["maxX"] and b["minY"] <= c["y"] <= b["maxY"], c
        d = min(math.dist((c["x"], c["y"]), p) for p in line)
        assert d <= t["roadHalfWidth"] + 1, ("off the road", c["name"], d)
        assert abs(d - abs(c["offset"])) < 15, ("not in its lane", c["name"], d, c["offset"])
        placed_seen.add(c["number"])
        checked += 1
    time.sleep(0.1)
print("ok", len(placed_seen), checked)
PY
)
contains "/api/state: the schema, every placed car on the road in its lane (4 cars)" "ok 4" "$result"
echo "  ($result)"

# /ws: the state first, then updates, at most 30 a second
# (Debian's python3 with python3-websocket, whatever python3 comes first on the PATH)
rate=$(timeout 30 /usr/bin/python3 - "$URL" <<'PY'
import json, sys, time, websocket
ws = websocket.create_connection(sys.argv[1].replace("http", "ws") + "ws", timeout=10)
first = json.loads(ws.recv())
assert first["type"] == "state", first["type"]
n, start = 0, time.monotonic()
while time.monotonic() - start < 3:
    m = json.loads(ws.recv())
    assert m["type"] == "update" and len(m["cars"]) == 4
    n += 1
elapsed = time.monotonic() - start
print("ok" if 30 <= n <= 30 * elapsed + 3 else "bad", n, round(elapsed, 2))
PY
)
contains "/ws: updates flow at no more than 30 a second" "ok" "$rate"
echo "  ($rate)"

# A body over 64 KiB (announced): 413 with a sentence, and the view serves on (docs/view.md's limits).
big=$(timeout 30 python3 - "$URL" <<'PY'
import socket, sys, urllib.parse, urllib.request
u = urllib.parse.urlparse(sys.argv[1])
s = socket.create_connection((u.hostname, u.port), timeout=10)
# the length announced, no byte of the body sent: the server answers on the header, and with
# nothing left unread its close is no reset that could drop the answer
s.sendall(b"POST /api/state HTTP/1.1\r\nHost: %s\r\nContent-Length: %d\r\n\r\n"
          % (u.netloc.encode(), 70 * 1024))
answer = b""
while True:
    try:
        chunk = s.recv(4096)
    except OSError:
        break
    if not chunk:
        break
    answer += chunk
status = answer.split(b"\r\n", 1)[0].decode()
said = b"the view takes no body over 64 KiB" in answer
again = urllib.request.urlopen(sys.argv[1] + "api/state", timeout=10).status
print(status, "| said" if said else "| not said", "| then", again)
PY
)
check "a body over 64 KiB: 413 with a sentence, and the view goes on" \
  "HTTP/1.1 413 Payload Too Large | said | then 200" "$big"

# 2. A port in use: refused with the port named and what to do; nothing started.
"$PITWALL" run "$SRC/examples/grand_prix.lua" --view "127.0.0.1:$port" --record "$TMP/busy.jsonl" \
  >"$TMP/busy.out" 2>"$TMP/busy.err"
check "a port in use: exit status 2" 2 "$?"
contains "a port in use: named" "127.0.0.1:$port" "$(cat "$TMP/busy.err")"
contains "a port in use: what to do" "--view 0 for any free port" "$(cat "$TMP/busy.err")"
check "a port in use: no frame went to a car" 0 "$(cat "$TMP/busy.jsonl" 2>/dev/null | grep -c '"dir":"tx"')"

# 3. Bad forms: the value and how to write it.
for bad in 99999 abc example.com:80 "1.2.3.4:"; do
  "$PITWALL" run "$SRC/examples/hello.lua" --view="$bad" >"$TMP/bad.out" 2>"$TMP/bad.err"
  check "--view=$bad: exit status 2" 2 "$?"
  contains "--view=$bad: names the value" "'$bad'" "$(cat "$TMP/bad.err")"
done

# 4. Another address only when asked: 0.0.0.0, with a warning.
start_view any run "$SRC/examples/grand_prix.lua" --view 0.0.0.0:0
port=${URL##*:}
port=${port%/}
check "--view 0.0.0.0:0 binds every address" "0.0.0.0" "$(listening_on "$port")"
contains "--view 0.0.0.0: warned" "anyone who can reach this machine can watch" "$(cat "$TMP/any.err")"

# 5. Out of file descriptors (a flood of connections against a low limit): the engine waits and
#    says so, it does not spin on accept(); once they are gone the view answers again.
( ulimit -n 64; exec "$PITWALL" run "$SRC/examples/grand_prix.lua" --view 127.0.0.1:0 \
    >"$TMP/fd.out" 2>"$TMP/fd.err" ) &
fdpid=$!
PIDS+=($fdpid)
wait_for "$TMP/fd.err" '^view: http://' 20 || fail "no view URL with 64 file descriptors"
URL=$(grep -oE '^view: http://[^ ]+' "$TMP/fd.err" | head -1 | sed 's/^view: //')
flood=$(timeout 60 python3 - "$URL" "$fdpid" <<'PY'
import os, socket, sys, time, urllib.request
url, pid = sys.argv[1], int(sys.argv[2])
host, port = url.split("//")[1].rstrip("/").split(":")
def cpu():  # utime + stime of the engine, seconds
    f = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")
held = []
for _ in range(100):
    s = socket.socket()
    s.settimeout(2)
    try:
        s.connect((host, int(port)))
        held.append(s)
    except OSError:
        s.close()
time.sleep(0.5)  # the engine takes what it can and then runs out
before = cpu()
time.sleep(2)
busy = cpu() - before
for s in held:
    s.close()
ok = False
deadline = time.time() + 10
while time.time() < deadline and not ok:
    try:
        ok = urllib.request.urlopen(url + "api/state", timeout=2).status == 200
    except OSError:
        time.sleep(0.1)
print("ok" if busy < 1.0 and ok else "bad", round(busy, 2), ok)
PY
)
contains "out of file descriptors: no spin (CPU of 2 s), the view answers after" "ok" "$flood"
echo "  ($flood)"
contains "out of file descriptors: said" "cannot take a browser's connection" "$(cat "$TMP/fd.err")"

# 6. The view on the REPL and on a bridge (the bridge without a broker: it keeps retrying, the
#    view shows its cars meanwhile).
mkfifo "$TMP/repl.in"
sleep 60 >"$TMP/repl.in" &
PIDS+=($!)
# (not through start_view: a command put in the background inside a function reads /dev/null)
"$PITWALL" repl --cars 2 --view 127.0.0.1:0 <"$TMP/repl.in" >"$TMP/repl.out" 2>"$TMP/repl.err" &
PIDS+=($!)
wait_for "$TMP/repl.err" '^view: http://' 20 || fail "repl --view: no URL in 20 s"
URL=$(grep -oE '^view: http://[^ ]+' "$TMP/repl.err" | head -1 | sed 's/^view: //')
cars=$(timeout 10 python3 -c 'import json,sys,urllib.request; print(len(json.load(urllib.request.urlopen(sys.argv[1]+"api/state"))["cars"]))' "$URL")
check "repl --view: the REPL's cars in the view" 2 "$cars"
[ "$cars" = 2 ] || sed 's/^/  | /' "$TMP/repl.err"

# a bridge whose broker is not there yet (a loopback port nobody listens on): it retries, and
# its view shows its cars meanwhile
start_view bridge bridge --mqtt mqtt://127.0.0.1:1 --cars 3 --view 127.0.0.1:0
cars=$(timeout 10 python3 -c 'import json,sys,urllib.request; print(len(json.load(urllib.request.urlopen(sys.argv[1]+"api/state"))["cars"]))' "$URL")
check "bridge --view: the bridge's cars in the view" 3 "$cars"

# --fast with --view: run, but said (a browser cannot follow a race in virtual time)
err=$(LAPS=1 SHOW=0 timeout 60 "$PITWALL" run "$SRC/examples/grand_prix.lua" --fast --cars 2 \
  --view 127.0.0.1:0 2>&1 >/dev/null); rc=$?
check "--fast --view: runs" 0 "$rc"
contains "--fast --view: said" "--view with --fast: the race runs faster than a browser can follow" "$err"
finish
