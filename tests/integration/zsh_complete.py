#!/usr/bin/python3
# zsh completes `pitwall` at a real prompt: an interactive zsh in a pseudo-terminal (pexpect)
# with the generated _pitwall on its fpath and compinit; Tab after what a user types lists what
# the completion offers. Used by cli_front_door_test.sh.
#
# usage: zsh_complete.py DIR   (DIR holds _pitwall and proj/ with grand.lua; exit 0 passed,
# 1 failed, 77 python3-pexpect missing)
import os
import sys

try:
    import pexpect
except ImportError:
    print("skip: python3-pexpect is not installed (./dev test installs it)")
    sys.exit(77)

DIR = sys.argv[1]
env = dict(os.environ, TERM="dumb", HOME=DIR, ZDOTDIR=DIR, PS1="%% ")
with open(os.path.join(DIR, ".zshrc"), "w") as rc:
    rc.write("fpath=(%s $fpath)\nautoload -Uz compinit && compinit -u -d %s/.zcompdump\n"
             "PS1='%%# '\nzstyle ':completion:*' list-rows-first true\nsetopt nobeep\n"
             "unsetopt zle_bracketed_paste 2>/dev/null\n" % (DIR, DIR))
failures = 0


def ask(typed, expected, what):
    """In a fresh interactive zsh, type `typed`, press Tab twice, expect every word of `expected`
    on the screen, in any order. A shell per question: nothing one question leaves behind (a
    listing still being drawn, an interrupted widget) reaches the next (clean-clone run 32 saw
    the shell end at the fifth question when one shell answered them all)."""
    global failures
    z = pexpect.spawn("zsh", ["-i"], cwd=os.path.join(DIR, "proj"), env=env, encoding="utf-8",
                      timeout=10, dimensions=(40, 200))
    try:
        z.expect("# ")
        z.send(typed + "\t\t")
        remaining = list(expected)
        while remaining:
            del remaining[z.expect_exact(remaining)]
        print("ok: zsh: " + what)
    except (pexpect.TIMEOUT, pexpect.EOF) as e:
        ended = "" if isinstance(e, pexpect.TIMEOUT) else (
            " (the shell ended: status %s, signal %s)" % (z.exitstatus, z.signalstatus))
        print("FAIL: zsh: %s: expected %s after %r, saw %r%s" % (what, expected, typed, z.before,
                                                                  ended))
        failures += 1
    z.close(force=True)


ask("pitwall r", ["repl", "replay", "run"], "commands, with their lines")
ask("pitwall run --tr", ["--track"], "a command's options")
ask("pitwall run --track ", ["oval", "kidney", "long"], "layout names")
ask("pitwall run gr", ["grand.lua"], "script files")
ask("pitwall track ", ["show"], "subcommands")
sys.exit(1 if failures else 0)
