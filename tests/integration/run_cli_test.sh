# pitwall run as a user runs it: broken scripts, a fast 10-minute race, deterministic recordings,
# Ctrl-C and a dying script stopping the cars.
source "$(dirname "$0")/lib.sh"

# A script that does not load: file and line on stderr, exit status 1.
printf 'local x = \nfor\n' > "$TMP/broken.lua"
err=$($PITWALL run "$TMP/broken.lua" --fast 2>&1 >/dev/null); rc=$?
check "syntax error exit status" 1 "$rc"
contains "syntax error names file and line" "broken.lua:2:" "$err"

err=$($PITWALL run "$TMP/missing.lua" --fast 2>&1 >/dev/null); rc=$?
check "missing script exit status" 2 "$rc"
contains "missing script is named" "missing.lua" "$err"

err=$($PITWALL run "$SRC/examples/lap_times.lua" --track nowhere 2>&1 >/dev/null); rc=$?
check "unknown track exit status" 2 "$rc"
contains "unknown track is named" "nowhere" "$err"

# More cars than a grid holds (four per piece, 36 on the oval): on the default track an oval
# long enough, said in one line; with --track given, an error naming what fits; sim.addCar on a
# full grid asks for a place.
cat > "$TMP/many.lua" <<'LUA'
print("cars", #pitwall.cars())
local ok, err = pcall(pitwall.sim.addCar, {})
print("addCar on a full grid:", ok, err)
print("addCar with a place:", pcall(pitwall.sim.addCar, { piece = 3, lane = 1 }) and "ok")
LUA
err=$($PITWALL run "$TMP/many.lua" --fast --duration 1 --cars 50 --track kidney 2>&1 >/dev/null); rc=$?
check "--cars beyond the --track's grid: exit status" 2 "$rc"
contains "--cars beyond the --track's grid: names what fits" \
  "50 cars do not fit the grid of kidney, which holds 44 (four on each piece); give a layout of at least 13 pieces, or leave out --track" "$err"
out=$($PITWALL run "$TMP/many.lua" --fast --duration 1 --cars 1000 2>"$TMP/many.err"); rc=$?
check "1000 cars: exit status" 0 "$rc"
contains "1000 cars: all on the track" "cars	1000" "$out"
contains "1000 cars: the longer oval is said" \
  "1000 cars do not fit the grid of oval, which holds 36 (four on each piece): racing on an oval of 251 pieces instead" \
  "$(cat "$TMP/many.err")"
out=$($PITWALL run "$TMP/many.lua" --fast --duration 1 --cars 36 2>&1); rc=$?
check "a full grid: exit status" 0 "$rc"
contains "sim.addCar on a full grid: the error asks for a place" \
  "the grid of oval is full (36 cars, four on each piece); give this car a place with piece= and lane=" "$out"
contains "sim.addCar with a place on a full grid" "addCar with a place:	ok" "$out"

# A 10-minute race of 4 cars in virtual time runs to its end.
cat > "$TMP/race.lua" <<'LUA'
local laps = 0
for i, car in ipairs(pitwall.cars()) do
  car.onTransition = function() laps = laps + 1 end
  car:setSpeed(500 + 100 * i)
end
pitwall.after(600, function()
  print(string.format("t=%.1f cars=%d transitions=%d", pitwall.now(), #pitwall.cars(), laps))
  pitwall.stop()
end)
LUA
out=$($PITWALL run "$TMP/race.lua" --fast --cars 4 2>/dev/null); rc=$?
check "fast race exit status" 0 "$rc"
contains "fast race reaches 600 s with 4 cars" "t=600.0 cars=4" "$out"

# Same seed, same recording, byte for byte; another seed changes it (speeds are random).
cat > "$TMP/random.lua" <<'LUA'
for _, car in ipairs(pitwall.cars()) do car:setSpeed(math.random(400, 900)) end
LUA
$PITWALL run "$TMP/random.lua" --fast --duration 20 --seed 7 --record "$TMP/a.jsonl" 2>/dev/null
$PITWALL run "$TMP/random.lua" --fast --duration 20 --seed 7 --record "$TMP/b.jsonl" 2>/dev/null
$PITWALL run "$TMP/random.lua" --fast --duration 20 --seed 8 --record "$TMP/c.jsonl" 2>/dev/null
lines=$(wc -l < "$TMP/a.jsonl")
[ "$lines" -gt 300 ] && echo "ok: recording has $lines frames" || fail "recording has only $lines frames"
cmp -s "$TMP/a.jsonl" "$TMP/b.jsonl" && echo "ok: same seed, identical recording" || fail "same seed gave different recordings"
cmp -s "$TMP/a.jsonl" "$TMP/c.jsonl" && fail "another seed gave the same recording" || echo "ok: another seed differs"
first=$(head -1 "$TMP/a.jsonl")
contains "record line has time, car, direction, hex and message" '"t":0.000000,"car":1,"dir":"tx","hex":"03 90 01 01","msg":{' "$first"

err=$($PITWALL run "$TMP/random.lua" --fast --record /nonexistent/dir/x.jsonl 2>&1); rc=$?
check "unwritable record file exit status" 2 "$rc"
contains "unwritable record file is named" "/nonexistent/dir/x.jsonl" "$err"

# The last command each car gets is speed 0 (set-speed with speed_mm_s 0).
last_speed_per_car() {
  grep '"name":"set-speed"' "$1" | sed -E 's/.*"car":([0-9]+).*"speed_mm_s":([0-9]+).*/\1 \2/' |
    awk '{last[$1]=$2} END {for (c in last) print c, last[c]}' | sort
}

# Ctrl-C in a real-time run: the cars are stopped, then pitwall exits with 130.
cat > "$TMP/forever.lua" <<'LUA'
for _, car in ipairs(pitwall.cars()) do car:setSpeed(600) end
pitwall.after(0.2, function() print("driving"); io.stdout:flush() end)
LUA
mkfifo "$TMP/out"
$PITWALL run "$TMP/forever.lua" --cars 2 --record "$TMP/int.jsonl" > "$TMP/out" 2>/dev/null &
pid=$!
exec 3< "$TMP/out"
read -r -t 20 line <&3  # waits for the script's "driving", i.e. the cars are under way
check "real-time run is driving" "driving" "$line"
kill -INT $pid
wait $pid; rc=$?
exec 3<&-
check "Ctrl-C exit status" 130 "$rc"
check "Ctrl-C stops every car" "1 0
2 0" "$(last_speed_per_car "$TMP/int.jsonl")"

# A script whose main chunk dies: cars stopped, exit status 1.
cat > "$TMP/dies.lua" <<'LUA'
for _, car in ipairs(pitwall.cars()) do car:setSpeed(700) end
pitwall.sleep(3)
error("the strategy crashed")
LUA
err=$($PITWALL run "$TMP/dies.lua" --fast --cars 3 --record "$TMP/dies.jsonl" 2>&1 >/dev/null); rc=$?
check "dying script exit status" 1 "$rc"
contains "dying script's error is shown with its line" "dies.lua:3: the strategy crashed" "$err"
check "a dying script's cars are stopped" "1 0
2 0
3 0" "$(last_speed_per_car "$TMP/dies.jsonl")"
# --results: checked before the race; the script's rows end up in the file
err=$($PITWALL run "$SRC/examples/hello.lua" --fast --results "$TMP/race.txt" 2>&1 >/dev/null); rc=$?
check "--results with an unknown extension: exit status" 2 "$rc"
contains "--results with an unknown extension: says why" "must end in .json or .csv" "$err"
err=$($PITWALL run "$SRC/examples/hello.lua" --fast --results "$TMP/nowhere/race.json" 2>&1 >/dev/null); rc=$?
check "--results in a missing folder: exit status" 2 "$rc"
contains "--results in a missing folder: names it" "cannot write results to" "$err"
printf '%s\n' "pitwall.writeResults({{position = 1, car = pitwall.cars()[1].name, laps = 0}}," \
  "  {'position', 'car', 'laps'})" "pitwall.stop()" >"$TMP/results.lua"
$PITWALL run "$TMP/results.lua" --fast --cars 1 --results "$TMP/race.csv" 2>/dev/null; rc=$?
check "--results: exit status" 0 "$rc"
check "--results: the file" "position,car,laps
1,groundshock,0" "$(cat "$TMP/race.csv")"

finish
