#!/usr/bin/python3
# `pitwall repl` as an operator uses it: through a real pseudo-terminal (pexpect), with GNU
# readline editing the line. Every wait is an expect with a timeout; nothing sleeps.
#
# usage: repl_pty_test.py PITWALL   (exit 0: passed, 1: failed, 77: python3-pexpect missing)
import json
import os
import re
import sys
import tempfile

try:
    import pexpect
except ImportError:
    print("skip: python3-pexpect is not installed (./dev test installs it)")
    sys.exit(77)

PITWALL = sys.argv[1]
TIMEOUT = 10  # seconds for anything to show up

# Terminal controls readline may put around a line (bracketed paste on/off, erase line) and
# carriage returns.
ESC = r"(?:\x1b\[[0-9;?]*[A-Za-z]|\r)*"
PROMPT = r"\n" + ESC + "> "  # a fresh "> " prompt (not the ">> " one)
MORE = r"\n" + ESC + ">> "


def value(text):
    """A line of its own holding exactly `text` (its final newline is left for the prompt)."""
    return r"\n" + ESC + re.escape(text) + r"\r(?=\n)"


SESSIONS = []  # every pitwall started, ended on a failure


class Session:
    def __init__(self, home, history, label, args=("repl",)):
        env = dict(os.environ, HOME=home, PITWALL_HISTORY=history, TERM="xterm",
                   INPUTRC="/dev/null")
        self.label = label
        self.child = pexpect.spawn(PITWALL, list(args), env=env, encoding="utf-8",
                                   timeout=TIMEOUT, dimensions=(40, 120))
        self.transcript = []
        self.child.logfile_read = self  # keeps everything the terminal showed
        SESSIONS.append(self.child)

    def write(self, text):  # pexpect's log file interface
        self.transcript.append(text)

    def flush(self):
        pass

    def output(self):
        return "".join(self.transcript)

    def expect(self, what, pattern, exact=False):
        try:
            if exact:
                self.child.expect_exact(pattern)
            else:
                self.child.expect(pattern)
        except (pexpect.TIMEOUT, pexpect.EOF) as e:
            tail = self.output()[-1500:]
            fail(f"{self.label}: {what}: expected {pattern!r}, got {type(e).__name__}; "
                 f"the terminal showed, last:\n{tail!r}")
        print(f"ok: {self.label}: {what}")

    def send(self, text):
        self.child.send(text)

    def line(self, text):
        self.child.send(text + "\r")

    def finish(self, what):
        self.expect(what + ": pitwall exits", pexpect.EOF)
        self.child.close()
        status = self.child.exitstatus
        if status != 0:
            fail(f"{self.label}: {what}: exit status {status} "
                 f"(signal {self.child.signalstatus}), expected 0")
        print(f"ok: {self.label}: {what}: exit status 0")


def fail(message):
    print("FAIL: " + message)
    for child in SESSIONS:
        if child.isalive():
            child.terminate(force=True)
    sys.exit(1)


def last_frames(record):
    """The last frame sent to each car in a --record file: {car: (name, speed)}."""
    last = {}
    with open(record, encoding="utf-8") as f:
        for line in f:
            r = json.loads(line)
            if r.get("dir") == "tx":
                last[r["car"]] = (r["msg"]["name"], r["msg"].get("speed_mm_s"))
    return last


def expect_stopped(what, record, cars):
    """docs/safety.md: the REPL's way out is the stop path, the last frame to every car its stop."""
    last = last_frames(record)
    want = {car: ("set-speed", 0) for car in range(1, cars + 1)}
    if last != want:
        fail(f"{what}: the last frame to each car should be its stop {want}, got {last}")
    print(f"ok: {what}: the last frame to every car is its stop")


def main():
    scratch = tempfile.mkdtemp(prefix="pitwall-repl-")
    history = os.path.join(scratch, "history")
    repl = Session(scratch, history, "session 1")
    repl.expect("banner names the cars", "pitwall repl: 4 cars", exact=True)
    repl.expect("first prompt", PROMPT)

    # Before any car drove, :cars shows where each stands: the grid's lanes, not 0.
    repl.line(":cars")
    repl.expect(":cars: car 1 stands at -68 mm before its first position update",
                r"1\s+groundshock\s+Groundshock\s+0\s+-\s+-68\.0\s+yes")
    repl.expect(":cars: car 4 at +68 mm", r"4\s+\S+\s+\S+\s+0\s+-\s+68\.0\s+yes")
    repl.expect("prompt after :cars", PROMPT)

    repl.line("=1+2")
    repl.expect("=1+2 prints 3", value("3"))
    repl.expect("prompt after a value", PROMPT)
    repl.line("cars[1].number + 10")
    repl.expect("an expression without = prints its value (cars[1] bound)", value("11"))
    repl.line("=#cars")
    repl.expect("#cars is the number of cars", value("4"))

    # A function over three lines, then called.
    repl.line("function add(a, b)")
    repl.expect("an unfinished chunk asks for more with >>", MORE)
    repl.line("  return a + b")
    repl.expect("still unfinished", MORE)
    repl.line("end")
    repl.expect("the finished chunk gives the > prompt back", PROMPT)
    repl.line("=add(2, 40)")
    repl.expect("the function defined over three lines works", value("42"))

    # A paste of several lines (bracketed: it arrives as one line) runs as if typed line by line.
    repl.send("\x1b[200~=10\n=20\x1b[201~\r")
    repl.expect("a pasted line shows its value", value("10"))
    repl.expect("and so does the next one", value("20"))
    repl.send("\x1b[200~function mul(a, b)\n  return a * b\nend\x1b[201~\r")
    repl.expect("a pasted function", PROMPT)
    repl.line("=mul(6, 7)")
    repl.expect("the pasted function is defined", value("42"))

    # Tab completes a car method; the completed line runs.
    repl.send("cars[1]:setSp")
    repl.expect("typed half a method name", "cars[1]:setSp", exact=True)
    repl.send("\t")
    repl.expect("Tab completes setSp to setSpeed", "eed", exact=True)
    repl.line("(600)")
    repl.expect("the completed call runs", PROMPT)
    if "attempt to call" in repl.child.before:
        fail("session 1: cars[1]:setSpeed(600) failed: " + repl.child.before)
    # Two Tabs list the candidates by their last part.
    repl.send("cars[1]:set\t\t")
    repl.expect("Tab Tab lists setOffset and setSpeed", r"setOffset\s+setSpeed")
    repl.child.sendintr()
    repl.expect("Ctrl-C drops the half-typed line", PROMPT)
    # The completer sees the whole line: brackets and quotes before the word do not hide it.
    repl.send('=("pit"):up\t')
    repl.expect("Tab completes a string method after a literal", "per", exact=True)
    repl.line("()")
    repl.expect("the completed string method runs", value('"PIT"'))
    repl.send('=cars["groundshock"]:setOf\t')
    repl.expect("Tab completes a method of a car named in brackets", "fset", exact=True)
    repl.child.sendintr()
    repl.expect("Ctrl-C drops that line", PROMPT)

    # help: the API from the binding's metadata and the annotations, one line each.
    repl.line("help()")
    repl.expect("help() says where to start", "help(cars[1])", exact=True)
    repl.expect("help() names Tab", "Tab", exact=True)
    repl.expect("prompt after help()", PROMPT)
    repl.line("help(cars[1])")
    repl.expect("help(cars[1]) names the car and its class", r"<car 1 groundshock: [^>]*>: pitwall\.Car")
    repl.expect("help(cars[1]) lists setSpeed with its parameters",
                "setSpeed(speed, accel?, respectLimit?)", exact=True)
    repl.expect("help(cars[1]) lists the fields", "fields (car.name, read only):", exact=True)
    repl.expect("help(cars[1]) lists the events", r"onPosition\s+each location code")
    repl.expect("prompt after help(cars[1])", PROMPT)
    if "_setHub" in repl.child.before:
        fail("session 1: help(cars[1]) shows an internal name: " + repl.child.before)
    for line in repl.child.before.split("\n"):
        if len(line.rstrip("\r")) > 120:
            fail(f"session 1: help(cars[1]) wrote a line wider than the terminal: {line!r}")
    print("ok: session 1: help(cars[1]): no internals, no line wider than the terminal")
    repl.line("help(pitwall.sim)")
    repl.expect("help(pitwall.sim) lists addCar", "pitwall.sim.addCar(spec?)", exact=True)
    repl.expect("prompt after help(pitwall.sim)", PROMPT)
    repl.line('help(require "pitwall.race")')
    repl.expect("help of a library module", "race.laps(options)", exact=True)
    repl.line("help(pitwall.after)")
    repl.expect("help of one function: in full", "pitwall.after(delay, fn) -> pitwall.Timer",
                exact=True)
    repl.line("help(42)")
    repl.expect("an unknown value gets one line", "help: no help for number 42", exact=True)
    repl.expect("prompt after help(42)", PROMPT)

    # Tab shows the API, not the internals: _names only once the _ is typed.
    repl.send("pitwall.\t\t")
    repl.expect("Tab Tab after pitwall. lists its names, then the line again",
                r"\n" + ESC + r"after\s[^>]*writeResults[^>]*> pitwall\.")
    if "_" in repl.child.after:
        fail("session 1: pitwall.<Tab><Tab> lists internals: " + repl.child.after)
    print("ok: session 1: pitwall.<Tab><Tab> lists no _name")
    repl.child.sendintr()
    repl.expect("Ctrl-C drops the line", PROMPT)
    repl.send("pitwall._setH\t")
    repl.expect("with the _ typed, Tab completes an internal", "ub", exact=True)
    repl.child.sendintr()
    repl.expect("Ctrl-C drops that line", PROMPT)
    repl.send("hel\t")
    repl.expect("Tab completes help, the prompt's own global", "p", exact=True)
    repl.child.sendintr()
    repl.expect("Ctrl-C drops the help line", PROMPT)

    # A chunk runs as a task: pitwall.sleep waits, the prompt comes back after it.
    repl.line("t0 = pitwall.now() pitwall.sleep(0.5) "
              "print(string.format('slept %.1f s', pitwall.now() - t0))")
    try:
        first = repl.child.expect([PROMPT, "slept 0.5 s"])
    except (pexpect.TIMEOUT, pexpect.EOF):
        fail("session 1: pitwall.sleep at the prompt: neither the prompt nor the end of the sleep "
             "came: " + repl.output()[-800:])
    if first != 1:
        fail("session 1: the prompt came back before the chunk's sleep ended")
    print("ok: session 1: pitwall.sleep(0.5) at the prompt waits; the prompt is not back before")
    repl.expect("the prompt comes back after the sleep", PROMPT)
    repl.line("=pitwall.sleep(0.2) or 'woke'")
    repl.expect("an expression that waits shows its value", value('"woke"'))
    # What is typed while a chunk waits runs once it is over.
    repl.line("print('waiting') pitwall.sleep(0.5)")
    repl.expect("the chunk waits", value("waiting"))
    repl.line("=6*7")
    repl.expect("the line typed during the wait runs after it", value("42"))
    repl.expect("and the prompt is back", PROMPT)
    # Ctrl-C during a sleep ends the chunk where it waits: it is cancelled, not left running.
    repl.line("woke = false print('sleeping') pitwall.sleep(0.5) woke = true")
    repl.expect("the chunk sleeps", value("sleeping"))
    repl.child.sendintr()
    repl.expect("Ctrl-C interrupts the sleeping chunk, naming the line it waited at",
                "stdin:1: interrupted while waiting", exact=True)
    repl.expect("the prompt comes back", PROMPT)
    repl.line("pitwall.sleep(1) print('woke: ' .. tostring(woke))")
    repl.expect("the interrupted chunk never woke up (a second sleep at the prompt works too)",
                value("woke: false"))

    # Ctrl-C out of an endless loop: the prompt comes back, the program and the cars go on.
    repl.line("print('spinning') while true do end")
    repl.expect("the endless loop is running", value("spinning"))
    repl.child.sendintr()
    repl.expect("Ctrl-C interrupts it", "interrupted", exact=True)
    repl.expect("and the prompt comes back", PROMPT)
    repl.line("=1+1")
    repl.expect("an expression evaluates after the interrupt", value("2"))
    repl.line("seen = nil")
    repl.line("watch = pitwall.every(0.05, function() local l = cars[1].location "
              "if seen == nil then seen = l elseif l ~= seen then "
              "print('moved from ' .. tostring(seen) .. ' to ' .. tostring(l)) watch:cancel() "
              "end end)")
    repl.expect("car 1 still drives after the interrupt (its location changes)",
                r"moved from \d+ to \d+")
    repl.line("=cars[1].speed > 0")
    repl.expect("and its speed is not 0", value("true"))

    # Ctrl-C at the prompt: the typed line is dropped, nothing is evaluated.
    repl.send("=999")
    repl.expect("typed a line", "=999", exact=True)
    repl.child.sendintr()
    repl.expect("Ctrl-C shows ^C", "^C", exact=True)
    repl.expect("and a fresh prompt", PROMPT)
    repl.line("=5")
    repl.expect("the dropped line is gone: =5 alone prints 5", value("5"))
    # … and the unfinished chunk of a >> prompt too.
    repl.line("function never()")
    repl.expect("an unfinished chunk", MORE)
    repl.child.sendintr()
    repl.expect("Ctrl-C at >> gives the > prompt", PROMPT)
    repl.line("=6")
    repl.expect("the unfinished chunk was dropped", value("6"))

    # A timer's print appears above the prompt; the half-typed line and its cursor survive.
    repl.line("n = 0 ticker = pitwall.every(0.2, function() n = n + 1 print('tick ' .. n) end)")
    repl.expect("a ticking timer", PROMPT)
    repl.send("=4+2")
    repl.expect("typed half a line", "=4+2", exact=True)
    repl.send("\x1b[D\x1b[D")  # the cursor two to the left, before "+"
    repl.expect("the tick prints above the prompt, which is drawn again with the typed text",
                r"tick \d+\r\n" + ESC + r"> =4\+2")
    repl.line("0")
    repl.expect("the line and the cursor survived: =40+2 prints 42", value("42"))
    repl.line("ticker:cancel()")
    repl.expect("timer cancelled", value("true"))

    repl.line(":cars")
    repl.expect(":cars lists the cars", r"#\s+name\s+model\s+speed\s+piece\s+offset\s+connected")
    repl.expect(":cars shows car 1", r"1\s+groundshock\s+Groundshock")
    repl.line(":nope")
    repl.expect("an unknown command is named", "unknown command :nope", exact=True)
    repl.line(":quit")
    repl.finish(":quit")

    try:
        with open(history, encoding="utf-8") as f:
            saved = f.read()
    except OSError as e:
        fail(f"the history file was not written: {e}")
    for entry in ["=1+2", "function add(a, b)\n  return a + b\nend", "cars[1]:setSpeed(600)",
                  ":quit"]:
        if entry not in saved:
            fail(f"the history file lacks {entry!r}: {saved!r}")
    print("ok: the history file holds the lines, a multi-line chunk as one entry")

    # The history is there in the next session; Ctrl-D at an empty prompt quits.
    repl = Session(scratch, history, "session 2")
    repl.expect("second session's prompt", PROMPT)
    repl.send("\x1b[A")
    repl.expect("Up recalls the last line of the first session", ":quit", exact=True)
    repl.child.sendintr()
    repl.expect("Ctrl-C drops it", PROMPT)
    # A runaway callback set up at the prompt is cut off by the budget; the prompt stays.
    repl.line("pitwall.after(0, function() while true do end end)")
    repl.expect("the runaway callback is reported above the prompt", "still running after 100 ms",
                exact=True)
    repl.expect("the prompt is drawn again", PROMPT)
    repl.line("=7*6")
    repl.expect("the prompt still evaluates", value("42"))
    repl.child.sendcontrol("d")
    repl.finish("Ctrl-D")

    # SIGTERM stops the cars and leaves with 130, as `pitwall run` does.
    repl = Session(scratch, history, "SIGTERM")
    repl.expect("the prompt comes up", PROMPT)
    repl.child.kill(15)
    repl.expect("SIGTERM says it stops the cars", "terminated: stopping the cars", exact=True)
    repl.expect("pitwall exits", pexpect.EOF)
    repl.child.close()
    if repl.child.exitstatus != 130:
        fail(f"SIGTERM: exit status {repl.child.exitstatus}, expected 130")
    print("ok: SIGTERM: exit status 130")

    # A history file that cannot be written: one warning, and the REPL works.
    repl = Session(scratch, "/nonexistent/folder/history", "unwritable history")
    repl.expect("the prompt comes up", PROMPT)
    repl.line("=1+2")
    repl.expect("values still print", value("3"))
    repl.line(":quit")
    repl.finish(":quit")
    warnings = repl.output().count("cannot write the history file /nonexistent/folder/history")
    if warnings != 1:
        fail(f"unwritable history: expected one warning, got {warnings}")
    print("ok: unwritable history: one warning")

    # pitwall run SCRIPT --repl --watch: the prompt is in the script's own world, and follows it
    # when a save reloads the script.
    script = os.path.join(scratch, "strategy.lua")
    with open(script, "w", encoding="utf-8") as f:
        f.write("laps = 0\n"
                "local car = pitwall.cars()[1]\n"
                "car:setSpeed(600)\n"
                "car.onTransition = function() laps = laps + 1 end\n"
                "function speedUp(s) car:setSpeed(s) return car.targetSpeed end\n"
                "function scriptSeesHelp() return help end\n"
                "pitwall.persist.version = 1\n")
    record = os.path.join(scratch, "watch.jsonl")
    repl = Session(scratch, history, "run --repl --watch",
                   ("run", script, "--repl", "--watch", "--cars", "1", "--record", record))
    repl.expect("the prompt comes up beside the script", PROMPT)
    repl.line("=type(laps) .. ' ' .. type(speedUp)")
    repl.expect("the script's globals are at hand", value('"number function"'))
    repl.line("=type(help) .. ' ' .. type(scriptSeesHelp())")
    repl.expect("help is the prompt's, not the script's", value('"function nil"'))
    repl.line("help(pitwall)")
    repl.expect("help works beside a script", "pitwall.after(delay, fn)", exact=True)
    repl.line("pitwall.sleep(0.2) print('slept beside the script')")
    repl.expect("sleep works beside a script", value("slept beside the script"))
    repl.line("=speedUp(700)")
    repl.expect("the script's function runs and commands its car", value("700"))
    repl.line("laps = 1000")
    repl.line("=laps >= 1000")
    repl.expect("a script variable changed at the prompt", value("true"))
    with open(script + ".new", "w", encoding="utf-8") as f:
        f.write("function speedUp(s) return -s end\n"
                "pitwall.persist.version = pitwall.persist.version + 1\n")
    os.rename(script + ".new", script)
    repl.expect("the reload is noted above the prompt", "the Lua world was reloaded", exact=True)
    repl.line("=pitwall.persist.version")
    repl.expect("the prompt now evaluates in the new version (persist carried over)", value("2"))
    repl.line("=speedUp(5)")
    repl.expect("and calls the new version's function", value("-5"))
    repl.line("=laps")
    repl.expect("the old version's globals are gone", value("nil"))
    repl.line(":quit")
    repl.finish("run --repl :quit")
    expect_stopped("run --repl :quit", record, 1)

    # Ctrl-D with a car driving and a timer commanding it every 20 ms: the stop path too.
    record = os.path.join(scratch, "ctrl-d.jsonl")
    nagging = os.path.join(scratch, "nagging.lua")
    with open(nagging, "w", encoding="utf-8") as f:
        f.write("pitwall.every(0.02, function()\n"
                "  for _, c in ipairs(pitwall.cars()) do c:setSpeed(900) end\n"
                "end)\n")
    repl = Session(scratch, history, "run --repl Ctrl-D",
                   ("run", nagging, "--repl", "--cars", "2", "--record", record))
    repl.expect("the prompt comes up beside the script", PROMPT)
    repl.line("pitwall.waitUntil(function() return pitwall.cars()[2].speed > 0 end, 5)")
    repl.expect("the prompt is back", PROMPT)
    repl.line("=pitwall.cars()[2].speed > 0")
    repl.expect("the cars drive", value("true"))
    repl.child.sendcontrol("d")
    repl.finish("run --repl Ctrl-D")
    expect_stopped("run --repl Ctrl-D", record, 2)


main()
