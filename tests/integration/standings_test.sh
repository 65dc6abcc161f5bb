# Standings that last (docs/league.md "Standings"): every league and `pitwall run` race is kept in
# a SQLite database; `pitwall standings` prints the table, per track and per driver, with personal
# bests. A second league adds to the first; a league killed in the middle keeps every race it had
# finished; a database of the older schema (version 1) is migrated and keeps its rows; a locked
# database holds the races and saves them beside it, and `standings import` adds them, so the table
# is the one no lock would have given; a corrupt, foreign, newer or read-only file is a sentence
# before anything races, and is left as it was.
source "$(dirname "$0")/lib.sh"
D="$SRC/tests/integration/drivers"
good_class "$TMP/class"
cp "$D/errors.lua" "$TMP/class/frank.lua"
export PITWALL_DB="$TMP/default.db"  # (the default database: never the home folder's)

league() {
  $PITWALL league "$TMP/class" --laps 2 --qualifying-laps 1 --seed 5 --cars 3 "$@"
}
# the table as JSON, one "driver points races wins" line each, in order
table() {
  $PITWALL standings --db "$1" --json "${@:2}" | python3 -c '
import json, sys
for r in json.load(sys.stdin)["standings"]:
    print(r["driver"], r["points"], r["races"], r["wins"])'
}
# each heat of a --results JSON as "heat driver position points" lines
heats_of() {
  python3 - "$1" <<'PY'
import json, sys
for h in json.load(open(sys.argv[1]))["heats"]:
    for r in h.get("results", []):
        print(h["heat"], r["driver"], r["position"], r["points"])
PY
}
# the same from a database
heats_in() {
  python3 - "$1" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
for row in db.execute("SELECT ra.number, r.driver, r.position, r.points FROM results r JOIN races "
                      "ra ON ra.id = r.race WHERE ra.kind = 'heat' ORDER BY ra.number, r.position"):
    print(*row)
PY
}

# races_of DB KIND: how many races of that kind the database keeps
races_of() {
  python3 -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute(
    'SELECT COUNT(*) FROM races WHERE kind = ?', (sys.argv[2],)).fetchone()[0])" "$1" "$2"
}
# hold_lock DB MODE: another program takes DB's lock (BEGIN MODE: IMMEDIATE or EXCLUSIVE) and
# holds it until release_lock; returns once it is held (false when it never was)
hold_lock() {
  rm -f "$TMP/lock.ready" "$TMP/lock.release"
  python3 - "$1" "$2" "$TMP/lock.ready" "$TMP/lock.release" <<'PY' &
import os, sqlite3, sys, time
db = sqlite3.connect(sys.argv[1], isolation_level=None)
db.execute("BEGIN " + sys.argv[2])
open(sys.argv[3], "w").close()
while not os.path.exists(sys.argv[4]):
    time.sleep(0.02)
db.execute("ROLLBACK")
PY
  LOCK_HOLDER=$!
  for _ in $(seq 1 500); do [ -e "$TMP/lock.ready" ] && return 0; sleep 0.02; done
  return 1
}
release_lock() { touch "$TMP/lock.release"; wait "$LOCK_HOLDER"; }

# A league is kept: its table is the league's own
league --db "$TMP/a.db" --results "$TMP/one.json" >"$TMP/one.out" 2>"$TMP/one.err"
check "a league: exit status" 0 "$?"
contains "a league says where its standings are" "kept in the standings: $TMP/a.db" "$(cat "$TMP/one.err")"
want=$(python3 - "$TMP/one.json" <<'PY'
import json, sys
for s in json.load(open(sys.argv[1]))["standings"]:
    print(s["driver"], s["points"], s["heats"], s["wins"])
PY
)
check "the kept table is the league's standings" "$want" "$(table "$TMP/a.db")"
check "the kept heats are the league's" "$(heats_of "$TMP/one.json")" "$(heats_in "$TMP/a.db")"
out=$($PITWALL standings --db "$TMP/a.db")
contains "standings: a table" "POS  DRIVER" "$out"
contains "standings: personal bests" "Personal bests" "$out"
contains "standings: a personal best on the track" "oval " "$(echo "$out" | sed -n '/Personal bests/,$p')"

# A second league adds to the first: every driver's points and races double
league --db "$TMP/a.db" >/dev/null 2>&1
doubled=$(echo "$want" | awk '{ print $1, 2 * $2, 2 * $3, 2 * $4 }')
check "a second league adds to the first" "$doubled" "$(table "$TMP/a.db")"
check "two leagues are two events" 2 "$($PITWALL standings --db "$TMP/a.db" --events --json |
  python3 -c 'import json,sys; print(len(json.load(sys.stdin)))')"
# per driver: its races, and its best lap is the smallest of its laps kept
out=$($PITWALL standings --db "$TMP/a.db" --driver alice --json)
best=$(echo "$out" | python3 -c '
import json, sys
d = json.load(sys.stdin)
laps = [r["bestLap"] for r in d["races"] if r["bestLap"] is not None]
pb = [b["lap"] for b in d["personalBests"]]
print(len(d["races"]), min(laps) == pb[0] and len(pb) == 1)')
check "standings --driver: qualifying and heats of two leagues, the personal best their best" \
  "$((2 * (1 + $(echo "$want" | awk '$1 == "alice" { print $3 }')))) True" "$best"
err=$($PITWALL standings --db "$TMP/a.db" --driver zed 2>&1); rc=$?
check "an unknown driver: status" 1 "$rc"
contains "an unknown driver: names the ones there are" "its drivers: " "$err"
check "--track: the table on one track" "$(table "$TMP/a.db")" "$(table "$TMP/a.db" --track oval)"
contains "--track: another track has no races" "no races yet on this track" \
  "$($PITWALL standings --db "$TMP/a.db" --track bowtie)"

# A league killed in the middle keeps every race it finished: more heats (six rounds), killed once
# the database has three of them; what is kept is the same as those heats of a whole run
league --db "$TMP/whole.db" --races 6 --results "$TMP/whole.json" >/dev/null 2>&1
# The poller starts the league itself, so that it looks from the league's first moment: started
# after it, on a loaded machine it once first looked when the league had already finished (clean-
# clone run 63), and killed nothing.
python3 - "$TMP/killed.db" "$PITWALL" "$TMP/class" <<'PY' || fail "killed: the league was still running when three heats were kept"
import signal, sqlite3, subprocess, sys, time
path, pitwall, folder = sys.argv[1:4]
league = subprocess.Popen([pitwall, "league", folder, "--laps", "2", "--qualifying-laps", "1",
                           "--seed", "5", "--cars", "3", "--db", path, "--races", "6"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
n = 0
for _ in range(20000):  # at most 100 s
    if league.poll() is not None:
        break
    try:
        db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        n = db.execute("SELECT COUNT(*) FROM races WHERE kind = 'heat'").fetchone()[0]
        db.close()
    except sqlite3.Error:
        n = 0
    if n >= 3:
        break
    time.sleep(0.005)
running = league.poll() is None
league.send_signal(signal.SIGKILL) if running else None
league.wait()
print(("ok: " if running else "FAIL: ") + f"killed: the league was killed with {n} heats kept")
sys.exit(0 if running else 1)
PY
kept=$(heats_in "$TMP/killed.db")
k=$(echo "$kept" | awk '{ print $1 }' | sort -un | wc -l)
[ "$k" -ge 3 ] && echo "ok: killed: $k heats were kept" || fail "killed: $k heats kept: $kept"
check "killed: the heats kept are those of a whole run" \
  "$(heats_of "$TMP/whole.json" | awk -v k="$k" '$1 <= k')" "$kept"
contains "killed: the event shows as not finished" "not finished" \
  "$($PITWALL standings --db "$TMP/killed.db" --events)"
$PITWALL standings --db "$TMP/killed.db" >/dev/null
check "killed: the database reads" 0 "$?"

# A database of schema version 1 (no reason, file or laps yet) migrates, and keeps its rows
python3 - "$TMP/old.db" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.executescript("""
CREATE TABLE events(id INTEGER PRIMARY KEY, kind TEXT NOT NULL, title TEXT NOT NULL,
  track TEXT NOT NULL, started TEXT NOT NULL, ended TEXT, details TEXT NOT NULL DEFAULT '{}');
CREATE TABLE races(id INTEGER PRIMARY KEY, event INTEGER NOT NULL REFERENCES events(id),
  kind TEXT NOT NULL, number INTEGER NOT NULL, track TEXT NOT NULL, laps INTEGER NOT NULL,
  ended TEXT NOT NULL, UNIQUE(event, kind, number));
CREATE TABLE results(race INTEGER NOT NULL REFERENCES races(id), number INTEGER NOT NULL,
  driver TEXT NOT NULL, car TEXT NOT NULL, position INTEGER, finished INTEGER NOT NULL,
  status TEXT NOT NULL, laps INTEGER NOT NULL, best_lap REAL, total_time REAL,
  points INTEGER NOT NULL, PRIMARY KEY(race, number));
CREATE INDEX results_driver ON results(driver);
INSERT INTO events VALUES(1, 'race', 'club night', 'oval', '2026-10-01T19:00:00Z',
  '2026-10-01T21:00:00Z', '{}');
INSERT INTO races VALUES(1, 1, 'race', 1, 'oval', 5, '2026-10-01T19:30:00Z');
INSERT INTO results VALUES(1, 1, 'alice', 'skull', 1, 1, 'finished', 5, 3.456, 18.2, 25);
INSERT INTO results VALUES(1, 2, 'zoe', 'nuke', 2, 1, 'finished', 5, 3.6, 18.9, 18);
PRAGMA user_version = 1;
""")
db.commit()
PY
out=$($PITWALL standings --db "$TMP/old.db" --json)
check "version 1: migrated to 3" 3 "$(python3 -c "import sqlite3; print(sqlite3.connect('$TMP/old.db').execute('PRAGMA user_version').fetchone()[0])")"
check "version 1: its rows are kept" "alice 25 1 1
zoe 18 1 0" "$(table "$TMP/old.db")"
contains "version 1: its personal best is kept" '"lap": 3.456' "$out"
league --db "$TMP/old.db" >/dev/null 2>&1
check "version 1: a league adds to it" \
  "$(echo "$want" | awk '$1 == "alice" { print $1, $2 + 25, $3 + 1, $4 + 1 }')" \
  "$(table "$TMP/old.db" | grep '^alice ')"

# A locked database: another program holds the write lock before the league starts and to its end
# (readers pass: the league opens the file, then cannot write). The league holds the races it
# cannot write, saves them beside the database and says how to add them; `standings import` adds
# them, and the table is the one without a lock. (Taken before the league, not after its first
# race: a poller racing the league lost on a busy machine, and the lock came too late or never.)
export PITWALL_DB_WAIT=0.2
python3 - "$TMP/a.db" "$TMP/locked.db" "$TMP/lock.ready" "$TMP/lock.release" <<'PY' &
import os, sqlite3, sys, time
schema_of, path, ready, release = sys.argv[1:5]
src = sqlite3.connect(schema_of)
db = sqlite3.connect(path, isolation_level=None)
for (sql,) in src.execute("SELECT sql FROM sqlite_master WHERE sql IS NOT NULL"):
    db.execute(sql)  # an empty standings database of the current schema
db.execute("PRAGMA user_version = %d" % src.execute("PRAGMA user_version").fetchone()[0])
db.execute("BEGIN IMMEDIATE")  # the write lock: readers pass, writers wait
open(ready, "w").close()
while not os.path.exists(release):
    time.sleep(0.02)
db.execute("ROLLBACK")
PY
LOCK_PID=$!
for _ in $(seq 500); do [ -e "$TMP/lock.ready" ] && break; sleep 0.02; done
league --db "$TMP/locked.db" >"$TMP/locked.out" 2>"$TMP/locked.err"
rc=$?
touch "$TMP/lock.release"
wait "$LOCK_PID"
check "locked: the league ends with status 1" 1 "$rc"
[ -e "$TMP/lock.ready" ] && echo "ok: locked: the lock was held during the league" ||
  fail "locked: the lock was never taken"
err=$(cat "$TMP/locked.err")
contains "locked: says the file is locked" "is locked by another program" "$err"
contains "locked: says what is held" "held and written with the next one or at the end" "$err"
unsaved=$(ls "$TMP"/locked.db.unsaved-*.json 2>/dev/null | head -1)
[ -n "$unsaved" ] && echo "ok: locked: the races are saved beside the database" ||
  fail "locked: no unsaved file: $err"
contains "locked: says how to add them" "pitwall standings --db $TMP/locked.db import $unsaved" "$err"
out=$($PITWALL standings --db "$TMP/locked.db" import "$unsaved"); rc=$?
check "import: exit status" 0 "$rc"
# (how many were held depends on when the lock came: one at least, the rest written before it)
held=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["races"]))' "$unsaved")
case "$held" in
  1) contains "import: says how many" "1 race from $unsaved added" "$out" ;;
  *) contains "import: says how many" "$held races from $unsaved added" "$out" ;;
esac
check "import: the table is the one without a lock" "$want" "$(table "$TMP/locked.db")"
check "import: one event, as it was raced" 1 "$($PITWALL standings --db "$TMP/locked.db" --events --json |
  python3 -c 'import json,sys; print(len(json.load(sys.stdin)))')"
err=$($PITWALL standings --db "$TMP/locked.db" import "$unsaved" 2>&1); rc=$?
check "import twice: status" 1 "$rc"
contains "import twice: a race is kept once" "already: a race is kept once" "$err"
check "import twice: the table is unchanged" "$want" "$(table "$TMP/locked.db")"
unset PITWALL_DB_WAIT

# Hostile unsaved files: each a sentence, no database made, nothing added (a review's findings)
printf '{"pitwall": 1, "races": []}' >"$TMP/typ.json"
mkdir -p "$TMP/adir.json"
python3 -c "print('{\"pitwall\": \"pitwall unsaved standings\", \"races\": [{\"kind\": ' + '[' * 300000 + ']' * 300000 + '}]}')" >"$TMP/deep.json"
printf '{"pitwall": "pitwall unsaved standings", "races": [{"entries": [{"car": "a", "position": 999999999, "finished": true}]}]}' >"$TMP/far.json"
printf '{"pitwall": "pitwall unsaved standings", "races": [' >"$TMP/cut.json"
mkfifo "$TMP/fifo.json"
for bad in "typ.json:not an unsaved standings file" "adir.json:not a file" \
  "deep.json:race.kind must be a string, got a list" \
  "far.json:position must be a place from 1 to 1 (the race's entries), got 999999999" \
  "cut.json:not JSON (" "fifo.json:not a file" "none.json:cannot be read ("; do
  f=${bad%%:*}
  err=$(timeout 20 $PITWALL standings --db "$TMP/imports.db" import "$TMP/$f" 2>&1); rc=$?
  check "import $f: status 1" 1 "$rc"
  contains "import $f: says what is wrong" "${bad#*:}" "$err"
done
check "hostile imports made no database" "" "$(ls "$TMP/imports.db" 2>/dev/null)"
# An unsaved file of a run whose event never reached the database: imported once, not twice
cat >"$TMP/once.json" <<'JSON'
{"pitwall": "pitwall unsaved standings", "token": "20261130T000000-1", "eventId": null,
 "event": {"kind": "race", "title": "club", "track": "oval"},
 "races": [{"kind": "race", "number": 1, "track": "oval", "laps": 3, "entries": [
   {"number": 1, "driver": "ann", "car": "skull", "position": 1, "finished": true, "laps": 3},
   {"number": 2, "driver": "bo", "car": "nuke", "position": 2, "finished": true, "laps": 3}]}]}
JSON
$PITWALL standings --db "$TMP/once.db" import "$TMP/once.json" >/dev/null
check "import: the races of an event that never reached the database" "ann 25 1 1
bo 18 1 0" "$(table "$TMP/once.db")"
err=$($PITWALL standings --db "$TMP/once.db" import "$TMP/once.json" 2>&1); rc=$?
check "import of it again: refused" 1 "$rc"
contains "import of it again: a race is kept once" "already: a race is kept once" "$err"
check "import of it again: the table is unchanged" "ann 25 1 1
bo 18 1 0" "$(table "$TMP/once.db")"
# An import cut short is finished by importing the file again: the races there already are left
python3 - "$TMP/once.json" "$TMP/part.json" <<'PY'
import json, sys
full = json.load(open(sys.argv[1]))
r1 = full["races"][0]
r2 = json.loads(json.dumps(r1)); r2["number"] = 2
full["races"] = [r1, r2]
full["token"] = "20261130T000000-2"
json.dump(dict(full, races=[r1]), open(sys.argv[2], "w"))
json.dump(full, open(sys.argv[2] + ".full", "w"))
PY
$PITWALL standings --db "$TMP/part.db" import "$TMP/part.json" >/dev/null
out=$($PITWALL standings --db "$TMP/part.db" import "$TMP/part.json.full"); rc=$?
check "an import finished: status" 0 "$rc"
contains "an import finished: the one race not there is added" "1 race from" "$out"
check "an import finished: both races, each once" "ann 50 2 2
bo 36 2 0" "$(table "$TMP/part.db")"
# Names are shown, never obeyed: a driver named with a terminal's escape codes
python3 - "$TMP/part.db" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE results SET driver = ? WHERE driver = 'ann'", ("\x1b[2J\x1b[31mEVIL\x07",))
db.commit()
PY
out=$($PITWALL standings --db "$TMP/part.db")
case "$out" in *$'\x1b'*|*$'\x07'*) fail "a name's escape codes reached the terminal: $(echo "$out" | cat -v)" ;;
  *) echo "ok: a name's escape codes are shown as text" ;; esac
contains "the name is shown escaped" '\x1b[2J\x1b[31mEVIL' "$out"
# A table of the user's own named as nothing of ours: the database takes races all the same
cp "$TMP/a.db" "$TMP/own.db"
python3 -c "import sqlite3; db = sqlite3.connect('$TMP/own.db'); db.execute('CREATE TABLE pitwall_probe(y)'); db.commit()"
league --db "$TMP/own.db" >/dev/null 2>&1
check "a user's own tables: the league is kept" 0 "$?"

# The database is none of a command's other files: it would be written over
cp "$TMP/a.db" "$TMP/same.db"
err=$($PITWALL run "$SRC/examples/hello.lua" --fast --cars 1 --db "$TMP/same.db" \
  --record "$TMP/same.db" 2>&1); rc=$?
check "--record onto --db: refused" 2 "$rc"
contains "--record onto --db: says why" "--record $TMP/same.db is the standings database" "$err"
ln "$TMP/same.db" "$TMP/hard.db"
err=$($PITWALL run "$SRC/examples/hello.lua" --fast --cars 1 --db "$TMP/same.db" \
  --record "$TMP/hard.db" 2>&1); rc=$?
check "--record onto a hard link of --db: refused" 2 "$rc"
err=$(league --db "$TMP/same.db" --results "$TMP/same.db" 2>&1); rc=$?
check "league --results onto --db: refused" 2 "$rc"
check "refused: the database is left as it was" "" "$(cmp "$TMP/a.db" "$TMP/same.db" 2>&1)"

# An empty --db (`--db "$UNSET"`) is no file: refused with a sentence, never the default database
for cmd in "league $TMP/class" "run $SRC/examples/grand_prix.lua --fast" "standings"; do
  err=$(XDG_DATA_HOME="$TMP/empty-xdg" $PITWALL $cmd --db '' 2>&1 >/dev/null); rc=$?
  check "--db '' ($cmd): refused" 2 "$rc"
  contains "--db '' ($cmd): says so" "the standings database's file name is empty" "$err"
done
check "--db '': no default database made" "" "$(ls -A "$TMP/empty-xdg" 2>/dev/null)"

# Files that cannot hold standings: a sentence before anything races, the file left as it was
refused() {  # NAME FILE EXPECTED-WORDS
  cp "$2" "$TMP/before"
  err=$(league --db "$2" 2>&1 >/dev/null); rc=$?
  check "$1: the league is refused" 2 "$rc"
  contains "$1: says what is wrong" "$3" "$err"
  case "$err" in *qualifying*) fail "$1: the league raced: $err" ;; *) echo "ok: $1: nothing raced" ;; esac
  check "$1: the file is left as it was" "" "$(cmp "$TMP/before" "$2" 2>&1)"
  err=$($PITWALL standings --db "$2" 2>&1); rc=$?
  check "$1: standings: status" 1 "$rc"
  contains "$1: standings: says what is wrong" "$3" "$err"
}
head -c 5000 /dev/urandom >"$TMP/noise.db"
refused "a file of noise" "$TMP/noise.db" "is not a pitwall standings database"
cp "$TMP/a.db" "$TMP/damaged.db"
python3 - "$TMP/damaged.db" <<'PY'
import sys
import os
size = os.path.getsize(sys.argv[1])
with open(sys.argv[1], "r+b") as f:  # page 2 onwards: the tables' own pages, scribbled over
    f.seek(4096)
    f.write((bytes(range(256)) * (size // 256 + 1))[: size - 4096])
PY
refused "a damaged database" "$TMP/damaged.db" "is damaged"
python3 -c "
import sqlite3; db = sqlite3.connect('$TMP/other.db'); db.execute('CREATE TABLE photos(x)'); db.commit()"
refused "another program's database" "$TMP/other.db" "not pitwall's standings (its tables: photos)"
cp "$TMP/a.db" "$TMP/newer.db"
python3 -c "import sqlite3; db = sqlite3.connect('$TMP/newer.db'); db.execute('PRAGMA user_version = 99'); db.commit()"
refused "a newer schema" "$TMP/newer.db" "has schema version 99, newer than this pitwall's 3"
# read-only: a file the user may not write (root may write any file: the check runs as nobody)
cp "$TMP/a.db" "$TMP/ro/a.db" 2>/dev/null || { mkdir -p "$TMP/ro" && cp "$TMP/a.db" "$TMP/ro/a.db"; }
chmod 755 "$TMP" "$TMP/ro" "$TMP/class"; chmod 644 "$TMP"/class/*.lua; chmod 444 "$TMP/ro/a.db"
as_user=()
[ "$(id -u)" = 0 ] && as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
err=$(PITWALL_DB= HOME=/nonexistent "${as_user[@]}" $PITWALL league "$TMP/class" --laps 1 \
  --qualifying-laps 1 --db "$TMP/ro/a.db" 2>&1 >/dev/null); rc=$?
check "read-only: the league is refused" 2 "$rc"
contains "read-only: says so" "cannot be written (read-only" "$err"
check "read-only: the file is left as it was" "" "$(cmp "$TMP/a.db" "$TMP/ro/a.db" 2>&1)"
out=$("${as_user[@]}" $PITWALL standings --db "$TMP/ro/a.db" 2>&1); rc=$?
check "read-only: its standings still read" 0 "$rc"
contains "read-only: the table" "POS  DRIVER" "$out"
err=$($PITWALL standings --db "$TMP/none.db" 2>&1); rc=$?
check "no database yet: status" 1 "$rc"
contains "no database yet: says so" "no standings at $TMP/none.db yet" "$err"
err=$($PITWALL standings --db "$TMP" 2>&1)
contains "a folder: says so" "is a folder" "$err"

# `pitwall run`: a race is kept in the default database, with who drove which car and its laps;
# --no-db keeps nothing
$PITWALL run "$SRC/examples/grand_prix.lua" --fast --results "$TMP/gp.json" >/dev/null \
  2>"$TMP/gp.err"
check "run: exit status" 0 "$?"
contains "run: says where the results are kept" "kept in the standings: $PITWALL_DB" "$(cat "$TMP/gp.err")"
want=$(python3 - "$TMP/gp.json" <<'PY'
import json, sys
pts = [25, 18, 15, 12, 10, 8, 6, 4, 2, 1]
for r in json.load(open(sys.argv[1])):
    print(r["car"], pts[r["position"] - 1] if r["finished"] else 0, 1, int(r["position"] == 1 and r["finished"]))
PY
)
check "run: the race's places are its table" "$want" "$(table "$PITWALL_DB")"
laps=$(python3 -c "
import sqlite3; db = sqlite3.connect('$PITWALL_DB')
print(db.execute('SELECT COUNT(*) FROM laps').fetchone()[0] == db.execute('SELECT SUM(laps) FROM results').fetchone()[0])")
check "run: every lap's time is kept" True "$laps"
$PITWALL run "$SRC/examples/grand_prix.lua" --fast --no-db >/dev/null 2>&1
check "run --no-db: nothing more is kept" "$want" "$(table "$PITWALL_DB")"
err=$($PITWALL run "$SRC/examples/grand_prix.lua" --fast --db "$TMP/noise.db" 2>&1 >/dev/null); rc=$?
check "run --db with a bad file: refused" 2 "$rc"
contains "run --db with a bad file: says why" "is not a pitwall standings database" "$err"

# A database locked when the run opens it: the run races, and its race is held and saved beside it
cp "$TMP/a.db" "$TMP/early.db"
hold_lock "$TMP/early.db" IMMEDIATE || fail "locked at the start: the lock was never taken"
PITWALL_DB_WAIT=0.3 $PITWALL run "$SRC/examples/grand_prix.lua" --fast --db "$TMP/early.db" \
  >/dev/null 2>"$TMP/early.err"
rc=$?
release_lock
check "locked at the start: the run races, and ends with status 1" 1 "$rc"
early=$(ls "$TMP"/early.db.unsaved-*.json 2>/dev/null | head -1)
[ -n "$early" ] && echo "ok: locked at the start: the race is saved beside the database" ||
  fail "locked at the start: nothing saved: $(cat "$TMP/early.err")"
$PITWALL standings --db "$TMP/early.db" import "$early" >/dev/null
check "locked at the start: imported, the race is there" 1 "$(races_of "$TMP/early.db" race)"

# Two races of one kind in one run are two races; a real-time run whose database is locked the
# whole time races on (the loop never waits for the lock: no car is stopped by the watchdog) and
# keeps its races beside it
cat >"$TMP/two.lua" <<'LUA'
local race = require "pitwall.race"
race.laps { laps = 1, board = false }
race.laps { laps = 1, board = false }
pitwall.stop()
LUA
$PITWALL run "$TMP/two.lua" --fast --cars 2 --db "$TMP/two.db" >/dev/null 2>"$TMP/two.err"
check "two races in a run: exit status" 0 "$?"
check "two races in a run: both kept" 2 "$(races_of "$TMP/two.db" race)"
cp "$TMP/two.db" "$TMP/held.db"
cat >"$TMP/rt.lua" <<'LUA'
local race = require "pitwall.race"
race.laps { laps = 1, board = false }
pitwall.stop()
LUA
# the lock is taken once the run has opened the database (its cars are connected after that)
PITWALL_DB_WAIT=2 $PITWALL run "$TMP/rt.lua" --cars 2 --db "$TMP/held.db" --record "$TMP/rt.jsonl" \
  >/dev/null 2>"$TMP/rt.err" &
RT_PID=$!
wait_for "$TMP/rt.err" "connected" 20 || fail "real time, locked: the run never connected its cars"
held=0
hold_lock "$TMP/held.db" EXCLUSIVE && held=1
wait "$RT_PID"
rc=$?
release_lock
[ "$held" = 1 ] && echo "ok: real time, locked: the lock was held during the race" ||
  fail "real time, locked: the lock was never taken"
check "real time, locked: exit status 1 (the race is not in the database)" 1 "$rc"
err=$(cat "$TMP/rt.err")
case "$err" in *"watchdog"*|*"loop was stuck"*) fail "real time, locked: the loop stood: $err" ;;
  *) echo "ok: real time, locked: the loop never stood for the lock" ;; esac
held=$(ls "$TMP"/held.db.unsaved-*.json 2>/dev/null | head -1)
[ -n "$held" ] && echo "ok: real time, locked: the race is saved beside the database" ||
  fail "real time, locked: no unsaved file: $err"
expect_stopped "real time, locked" "$TMP/rt.jsonl" 2
$PITWALL standings --db "$TMP/held.db" import "$held" >/dev/null
check "real time, locked: imported, the run's race is there" 3 "$(races_of "$TMP/held.db" race)"

[ "$FAILURES" -eq 0 ] || { echo "$FAILURES failure(s)"; exit 1; }
echo "all standings checks passed"
