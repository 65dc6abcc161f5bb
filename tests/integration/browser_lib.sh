# Shared by the browser tests (view_browser_test, drive_browser_test), sourced after lib.sh: the
# browsers and node they need, puppeteer-core in a folder of the build tree, a pitwall run with
# --view ($pid, killed at exit) and its address. The checks in the browser are tests/view/*.mjs,
# on tests/view/check_lib.mjs.

# $pid: the pitwall run in the background, if any; killed at exit, with $TMP removed.
pid=""
cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  rm -rf "$TMP"
}
trap cleanup EXIT

# Real parts: no browser or no node is a failure, not a skip (./dev test installs them).
CHROMIUM=${CHROMIUM:-/usr/bin/chromium}
FIREFOX=${FIREFOX:-/usr/bin/firefox-esr}
command -v node >/dev/null || { echo "FAIL: node is missing; install nodejs (./dev test does)"; exit 1; }
command -v npm >/dev/null || { echo "FAIL: npm is missing; install npm (./dev test does)"; exit 1; }
[ -x "$CHROMIUM" ] || { echo "FAIL: no Chromium at $CHROMIUM; install chromium (./dev test does) or set CHROMIUM"; exit 1; }

# need_firefox: Firefox ESR at $FIREFOX, or a FAIL and exit.
need_firefox() {
  [ -x "$FIREFOX" ] || { echo "FAIL: no Firefox at $FIREFOX; install firefox-esr (./dev test does) or set FIREFOX"; exit 1; }
}

# install_checks FOLDER CHECK.mjs...: puppeteer-core (tests/view/package-lock.json) installed once
# in ./FOLDER of the build tree, again when the lockfile changes; a folder for each test, so that
# the tests may run at once. The check scripts and check_lib.mjs are copied beside its
# node_modules, so that `import "puppeteer-core"` resolves. Sets $CHECK to the folder.
install_checks() {
  CHECK="$PWD/$1"
  shift
  mkdir -p "$CHECK"
  if ! cmp -s "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock" ||
     [ ! -d "$CHECK/node_modules/puppeteer-core" ]; then
    cp "$SRC/tests/view/package.json" "$SRC/tests/view/package-lock.json" "$CHECK/"
    if ! (cd "$CHECK" && timeout 300 npm ci --no-audit --no-fund --prefer-offline --loglevel=error); then
      echo "FAIL: npm ci of tests/view (puppeteer-core) in $CHECK"
      exit 1
    fi
    cp "$SRC/tests/view/package-lock.json" "$CHECK/installed.lock"
  fi
  local script
  for script in check_lib.mjs "$@"; do cp "$SRC/tests/view/$script" "$CHECK/"; done
}

# artifacts GLOB: $ART is ./view_test_artifacts (screenshots), with the files GLOB of an earlier
# run removed.
artifacts() {
  ART="$PWD/view_test_artifacts"
  mkdir -p "$ART"
  rm -f "$ART"/$1
}

# start_drive_race: tests/view/drive_race.lua in real time, its view on a free port of loopback
# with two seats (--humans 2 --cars 2, 300 s); its output in $TMP/out and $TMP/err, $pid the run.
start_drive_race() {
  "$PITWALL" run "$SRC/tests/view/drive_race.lua" --view 127.0.0.1:0 --humans 2 --cars 2 \
    --duration 300 > "$TMP/out" 2> "$TMP/err" &
  pid=$!
}

# await_view STDERR [NAME]: until pitwall's "view: http://127.0.0.1:PORT/" line is in the file
# STDERR (at most 20 s), then $url is that address. False, with a FAIL and the file shown, when it
# never came.
await_view() {
  url=""
  if ! wait_for "$1" '^view: http://127\.0\.0\.1:[0-9]+/' 20; then
    fail "pitwall printed no 'view: http://127.0.0.1:PORT/' line within 20 s; its stderr:"
    sed 's/^/  | /' "$1" | tail -40
    return 1
  fi
  url=$(grep -oE '^view: http://127\.0\.0\.1:[0-9]+/' "$1" | head -1 | sed 's/^view: //')
  echo "ok: view at $url${2:+ ($2)}"
}

# await_code STDERR: until a run on 0.0.0.0 prints its join code ("view: join code 123456: …", at
# most 20 s); then $code is the code and $port the view's port. False when it never came.
await_code() {
  wait_for "$1" '^view: join code [0-9]{6}: ' 20 || return 1
  code=$(grep -oE '^view: join code [0-9]{6}' "$1" | head -1 | grep -oE '[0-9]{6}$')
  port=$(grep -oE '^view: http://0\.0\.0\.0:[0-9]+/' "$1" | head -1 | grep -oE '[0-9]+/$' | tr -d /)
}

# await_end NAME SECONDS STATUS: until $pid ends (at most SECONDS), then checks its exit status is
# STATUS and forgets $pid; a FAIL when it still runs.
await_end() {
  local deadline=$((SECONDS + $2))
  while kill -0 "$pid" 2>/dev/null && [ $SECONDS -lt $deadline ]; do sleep 0.05; done
  if kill -0 "$pid" 2>/dev/null; then
    fail "$1 still runs $2 s later"
  else
    wait "$pid"
    check "$1: exit status" "$3" "$?"
    pid=""
  fi
}

# show_if_failed WHAT FILE: the end of FILE, when a check failed so far.
show_if_failed() {
  if [ "$FAILURES" -ne 0 ]; then
    echo "$1:"
    sed 's/^/  | /' "$2" | tail -40
  fi
}
