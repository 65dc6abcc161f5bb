# The worst case over many seeds (docs/simulator.md "Sensor model"): a race whose cars send not
# one position update holds its laps, order, gaps and stop against the ground truth
# (tests/scenarios/race_transitions_test.lua) for every seed, not only the scenario's own.
source "$(dirname "$0")/lib.sh"
for seed in 2 3 4 5 6 7; do
  out=$($PITWALL test "$SRC/tests/scenarios/race_transitions_test.lua" --seed "$seed" 2>&1)
  rc=$?
  check "transitions only, seed $seed" 0 "$rc"
  [ "$rc" -eq 0 ] || echo "$out" | tail -20
done
finish
