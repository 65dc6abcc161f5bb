# --keyboard: without a terminal, one sentence and status 2; then the arrow keys through a real
# pseudo-terminal drive car 1 (keyboard_pty_test.py, python3-pexpect; docs/controllers.md).
source "$(dirname "$0")/lib.sh"

out=$(echo | $PITWALL run "$SRC/tests/integration/human_seat1.lua" --humans 1 --keyboard \
  --duration 1 2>&1); rc=$?
check "--keyboard from a pipe: exit status" 2 "$rc"
contains "--keyboard from a pipe: says why" "--keyboard needs a terminal: the standard input is not one" "$out"
out=$($PITWALL run "$SRC/tests/integration/human_seat1.lua" --keyboard --duration 1 2>&1); rc=$?
check "--keyboard without --humans: exit status" 2 "$rc"

finish
if [ ! -x /usr/bin/python3 ]; then
  echo "skip: the terminal half needs /usr/bin/python3 with python3-pexpect (./dev test installs it)"
  exit 77
fi
/usr/bin/python3 "$(dirname "$0")/keyboard_pty_test.py" "$PITWALL" "$SRC"
