#!/usr/bin/python3
# `pitwall run --humans 1 --keyboard` as a player uses it (docs/controllers.md "Keyboard"): on a
# real pseudo-terminal (pexpect), the arrow keys drive car 1 of the simulator through the race
# library's human driver; space stops it; the terminal is in cbreak mode while it drives and as it
# was once pitwall has exited — after the run's end and after Ctrl-C; a terminal that closes under
# it (SIGHUP) ends the run through its stop path. Every wait has a timeout.
#
# usage: keyboard_pty_test.py PITWALL SOURCE_DIR  (exit 0 passed, 1 failed, 77 no python3-pexpect)
import json
import os
import pty
import re
import select
import shutil
import signal
import sys
import tempfile
import termios
import time

try:
    import pexpect
except ImportError:
    print("skip: python3-pexpect is not installed (./dev test installs it)")
    sys.exit(77)

PITWALL, SRC = sys.argv[1], sys.argv[2]
SCRIPT = os.path.join(SRC, "tests/integration/human_seat1.lua")
TIMEOUT = 15
UP, DOWN, LEFT, RIGHT = "\x1b[A", "\x1b[B", "\x1b[D", "\x1b[C"
LINE = re.compile(r"seat 1: holder=(\S+) throttle=([0-9.]+) speed=-?\d+ moving=(yes|no)")
failures = []


def check(what, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + what + (f": {detail}" if detail and not ok else ""))
    if not ok:
        failures.append(what)


def spawn(*extra):
    child = pexpect.spawn(PITWALL, ["run", SCRIPT, "--humans", "1", "--keyboard", *extra],
                          encoding="utf-8", timeout=TIMEOUT, dimensions=(40, 120),
                          env=dict(os.environ, TERM="xterm"))
    child.logfile_read = sys.stdout
    return child


def lflag(child):
    return termios.tcgetattr(child.child_fd)[3]


def fresh_modes():
    """The modes of a pty as pexpect makes it, before anything changes them (a `cat` holds it)."""
    ref = pexpect.spawn("cat", encoding="utf-8", timeout=TIMEOUT, env=dict(os.environ, TERM="xterm"))
    ref.sendline("ready")
    ref.expect("ready")
    modes = termios.tcgetattr(ref.child_fd)
    ref.close(force=True)
    return modes


def wait_for(child, what, test):
    """Reads the script's lines until test(holder, throttle, moving) holds; the last match."""
    while True:
        child.expect(LINE)
        holder, throttle, moving = (child.match.group(1), float(child.match.group(2)),
                                    child.match.group(3) == "yes")
        if test(holder, throttle, moving):
            return holder, throttle, moving


def run_until_end():
    before = fresh_modes()
    check("a fresh pty is canonical, with echo",
          bool(before[3] & termios.ICANON and before[3] & termios.ECHO))
    child = spawn("--duration", "30")
    child.expect("keyboard: driving car 1")
    during = lflag(child)
    check("while it drives: no ICANON, no ECHO (cbreak)",
          not (during & termios.ICANON) and not (during & termios.ECHO))
    check("while it drives: ISIG kept (Ctrl-C is still a signal)", bool(during & termios.ISIG))
    wait_for(child, "the keyboard holds seat 1", lambda h, t, s: h == "keyboard")
    check("the keyboard holds seat 1", True)

    child.send(UP * 5)  # throttle 0.5
    _, throttle, _ = wait_for(child, "throttle 0.5", lambda h, t, s: t >= 0.5)
    check("five ↑ ask for throttle 0.5", abs(throttle - 0.5) < 1e-9, str(throttle))
    wait_for(child, "car 1 drives", lambda h, t, m: m)
    check("car 1 drives", True)

    # split across writes: ESC, then [B a moment later
    child.send("\x1b")
    child.send("[B")
    _, throttle, _ = wait_for(child, "throttle 0.4", lambda h, t, s: t < 0.5)
    check("↓ sent in two pieces takes a tenth off", abs(throttle - 0.4) < 1e-9, str(throttle))
    child.send(LEFT)  # a lane change on the way (the driver takes it; nothing to wait for)

    child.send(" ")
    _, throttle, _ = wait_for(child, "throttle 0", lambda h, t, s: t == 0)
    check("space asks for throttle 0", throttle == 0)
    wait_for(child, "car 1 stands", lambda h, t, m: not m)
    check("car 1 slows to a stop (no position report for 0.5 s)", True)

    child.send(UP * 3)
    wait_for(child, "driving again", lambda h, t, m: m)
    child.sendintr()  # Ctrl-C: SIGINT through the terminal (ISIG)
    child.expect(pexpect.EOF)
    child.wait()  # the exit status, read before close()
    after = termios.tcgetattr(child.child_fd)
    check("Ctrl-C ends the run (status 0 or 130)", child.exitstatus in (0, 130) or
          child.signalstatus == 2, f"{child.exitstatus}/{child.signalstatus}")
    check("after Ctrl-C the terminal's modes are as before", after == before,
          f"{after} != {before}")
    child.close()


def run_to_duration():
    before = fresh_modes()
    child = spawn("--duration", "2")
    child.expect("keyboard: driving car 1")
    child.send(UP * 2)
    child.expect("the run's duration is over")
    child.expect(pexpect.EOF)
    child.wait()
    after = termios.tcgetattr(child.child_fd)
    check("--duration ends the run with status 0", child.exitstatus == 0, str(child.exitstatus))
    check("at the run's end the terminal's modes are as before", after == before,
          f"{after} != {before}")
    child.close()


def run_hung_up():
    """The terminal closes under a driving keyboard (a window shut, SSH dropped): the kernel sends
    SIGHUP, which must end the run like SIGTERM — every car stopped, status 130 — not kill it."""
    tmp = tempfile.mkdtemp(prefix="pitwall-hup-")
    record, log = os.path.join(tmp, "run.jsonl"), os.path.join(tmp, "stderr")
    pid, master = pty.fork()  # pitwall leads a new session, the pty its controlling terminal
    if pid == 0:
        err = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.dup2(err, 2)  # the log outlives the terminal
        # as a terminal's shell starts it: a test run under nohup would pass SIGHUP on ignored
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
        os.execve(PITWALL, [PITWALL, "run", SCRIPT, "--humans", "1", "--keyboard", "--duration",
                            "30", "--record", record], dict(os.environ, TERM="xterm"))
    seen = ""

    def expect(pattern):
        nonlocal seen
        deadline = time.monotonic() + TIMEOUT
        while not re.search(pattern, seen):
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([master], [], [], left)[0]:
                raise pexpect.TIMEOUT(f"no {pattern!r} on the terminal")
            seen += os.read(master, 4096).decode("utf-8", "replace")
        seen = seen[re.search(pattern, seen).end():]

    try:
        expect(r"holder=keyboard")
        os.write(master, (UP * 5).encode())
        expect(r"holder=keyboard throttle=0\.50 speed=\d+ moving=yes")
        check("hang-up: the keyboard drives car 1", True)
    except pexpect.TIMEOUT:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        raise
    os.close(master)  # the terminal is gone: SIGHUP to pitwall, EIO on its reads
    deadline = time.monotonic() + TIMEOUT
    while (done := os.waitpid(pid, os.WNOHANG))[0] == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    if done[0] == 0:
        os.kill(pid, signal.SIGKILL)
        done = os.waitpid(pid, 0)
    status = done[1]
    check("hang-up: pitwall exits with status 130, not killed by SIGHUP",
          os.WIFEXITED(status) and os.WEXITSTATUS(status) == 130,
          f"exit {os.WEXITSTATUS(status)}" if os.WIFEXITED(status)
          else f"signal {os.WTERMSIG(status)}")
    text = open(log, encoding="utf-8", errors="replace").read()
    check("hang-up: the log says the cars are stopped", "hung up: stopping the cars" in text,
          text[-400:])
    last = {}
    for line in open(record, encoding="utf-8"):
        r = json.loads(line)
        if r.get("dir") == "tx":  # (a race's own lines in a record have no "dir")
            last[r["car"]] = r["msg"]
    stops = {car: m["name"] == "set-speed" and m.get("speed_mm_s") == 0 for car, m in last.items()}
    check("hang-up: the last frame to every car is its stop", bool(stops) and all(stops.values()),
          str(last))
    shutil.rmtree(tmp, ignore_errors=True)


try:
    run_until_end()
    run_to_duration()
    run_hung_up()
except (pexpect.TIMEOUT, pexpect.EOF) as e:
    failures.append(f"pitwall did not show what was expected: {type(e).__name__}")
    print(f"\nFAIL: {type(e).__name__} waiting for the expected output")
print(f"\n{len(failures)} failed" if failures else "\nall passed")
sys.exit(1 if failures else 0)
