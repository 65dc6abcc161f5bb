# The LuaLS definitions (docs/editor.md): types/ in the repository is what this binary generates
# from its own metadata (so it cannot drift), and `pitwall types DIR` writes them with a
# .luarc.json for a user's project, merging into one that exists.
source "$(dirname "$0")/lib.sh"

# 1. the checked-in definitions are the binary's
mkdir -p "$TMP/gen"
out=$($PITWALL types "$TMP/gen" 2>&1); rc=$?
check "pitwall types exit status" 0 "$rc"
contains "pitwall types says what it wrote" "definition files to $TMP/gen/types" "$out"
if diff -ru "$SRC/types" "$TMP/gen/types" >"$TMP/types.diff"; then
  echo "ok: types/ is what the binary generates"
else
  cat "$TMP/types.diff"
  fail "types/ differs from what the binary generates (the diff above); regenerate it from the repository root with: build/pitwall types --no-luarc . (docs/editor.md)"
fi
out=$($PITWALL types --check "$SRC" 2>&1); rc=$?
check "types --check on the repository" 0 "$rc"

# 2. --check names a file that differs, and how to regenerate
cp -r "$SRC/types" "$TMP/stale-types"
mkdir -p "$TMP/stale" && mv "$TMP/stale-types" "$TMP/stale/types"
echo "-- edited by hand" >>"$TMP/stale/types/pitwall/race.lua"
echo "---@meta" >"$TMP/stale/types/pitwall/gone.lua"
out=$($PITWALL types --check "$TMP/stale" 2>&1); rc=$?
check "types --check on edited definitions" 1 "$rc"
contains "names the file that differs" "differs: $TMP/stale/types/pitwall/race.lua" "$out"
contains "names a file not generated" "not generated (stale): $TMP/stale/types/pitwall/gone.lua" "$out"
contains "says how to regenerate" "regenerate with \`pitwall types $TMP/stale\`" "$out"

# 3. a project's .luarc.json: made, kept, merged, or left alone when it is not JSON
json() { python3 -c "import json,sys; c=json.load(open(sys.argv[1])); print($2)" "$1"; }
check ".luarc.json library" "['types']" "$(json "$TMP/gen/.luarc.json" "c['workspace']['library']")"
check ".luarc.json runtime" "Lua 5.4" "$(json "$TMP/gen/.luarc.json" "c['runtime']['version']")"
out=$($PITWALL types "$TMP/gen" 2>&1)
contains "a second run keeps .luarc.json" "kept $TMP/gen/.luarc.json" "$out"

mkdir -p "$TMP/user"
printf '{\n  "diagnostics": {"globals": ["love"]},\n  "workspace": {"library": ["lib"]}\n}\n' >"$TMP/user/.luarc.json"
out=$($PITWALL types "$TMP/user" 2>&1); rc=$?
check "merging exit status" 0 "$rc"
contains "says it updated" "updated $TMP/user/.luarc.json" "$out"
check "merged library" "['lib', 'types']" "$(json "$TMP/user/.luarc.json" "c['workspace']['library']")"
check "the user's settings stay" "['love']" "$(json "$TMP/user/.luarc.json" "c['diagnostics']['globals']")"

mkdir -p "$TMP/one" "$TMP/dot" "$TMP/commented"
echo '{"workspace.library": "libs"}' >"$TMP/one/.luarc.json"
$PITWALL types "$TMP/one" >/dev/null 2>&1
check "a library given as one string is kept beside types" "['libs', 'types']" "$(json "$TMP/one/.luarc.json" "c['workspace.library']")"
echo '{"workspace": {"library": ["./types/"]}}' >"$TMP/dot/.luarc.json"
out=$($PITWALL types "$TMP/dot" 2>&1)
contains "./types/ counts as types" "kept $TMP/dot/.luarc.json" "$out"
printf '{\n  // mine\n  "workspace": {"library": ["lib"]}\n}\n' >"$TMP/commented/.luarc.json"
before=$(cat "$TMP/commented/.luarc.json")
out=$($PITWALL types "$TMP/commented" 2>&1); rc=$?
check "a .luarc.json with comments: exit status" 1 "$rc"
contains "a .luarc.json with comments is named" "has comments, which rewriting it would lose" "$out"
check "a .luarc.json with comments is left as it was" "$before" "$(cat "$TMP/commented/.luarc.json")"

mkdir -p "$TMP/broken"
echo "not json" >"$TMP/broken/.luarc.json"
out=$($PITWALL types "$TMP/broken" 2>&1); rc=$?
check "a .luarc.json that is not JSON: exit status" 1 "$rc"
contains "says it left it" "is not a JSON object: left as it is" "$out"
check "it is left as it was" "not json" "$(cat "$TMP/broken/.luarc.json")"
[ -f "$TMP/broken/types/pitwall.lua" ] && echo "ok: the definitions are written all the same" ||
  fail "no definitions in $TMP/broken/types"

out=$($PITWALL types "$TMP/nowhere" 2>&1); rc=$?
check "a folder that does not exist: exit status" 2 "$rc"
contains "names it" "$TMP/nowhere is not a folder" "$out"

# 5. an editor's completions (the view's code editor, docs/view.md) come from the same
# definitions: after car: every method of pitwall.Car in types/pitwall.lua (which step 1 checked
# against the binary), after car. its fields and events, after ctx: the driver context's methods
out=$($PITWALL types --completions "$TMP/completions.json" 2>&1); rc=$?
check "types --completions exit status" 0 "$rc"
contains "says what it wrote" "completions under" "$out"
labels() { json "$TMP/completions.json" "' '.join(m['label'] for m in c['$1'])"; }
defined() { grep -oE "^function $1[:.][A-Za-z_]+" "$2" | sed -E "s/^function $1[:.]//" | sort | tr '\n' ' ' | sed 's/ $//'; }
check "car: offers pitwall.Car's methods, as defined" "$(defined Car "$SRC/types/pitwall.lua")" "$(labels car:)"
check "ctx: offers the driver context's methods, as defined" \
  "$(defined Context "$SRC/types/pitwall/drivers.lua")" "$(labels ctx:)"
check "pitwall.sim. offers its functions, as defined" \
  "$(defined pitwall.sim "$SRC/types/pitwall.lua" | tr ' ' '\n' | sort | tr '\n' ' ' | sed 's/ $//')" \
  "$(json "$TMP/completions.json" "' '.join(sorted(m['label'] for m in c['pitwall.sim.'] if m['type'] == 'function'))")"
contains "car. offers its fields and events" "speed" "$(labels car.)"
contains "car. offers its events" "onTransition" "$(labels car.)"
check "setSpeed's completion says its parameters and what it does" \
  "(speed, accel, respectLimit) | Sets the speed (frame 0x24)." \
  "$(json "$TMP/completions.json" "[m['detail'] + ' | ' + m['info'] for m in c['car:'] if m['label'] == 'setSpeed'][0]")"
check "globals: pitwall among them" "pitwall" \
  "$(json "$TMP/completions.json" "[m['label'] for m in c[''] if m['label'] == 'pitwall'][0]")"

# 4. examples/ uses the repository's definitions
check "examples/.luarc.json library" "['../types']" "$(json "$SRC/examples/.luarc.json" "c['workspace']['library']")"
check "examples/.luarc.json runtime" "Lua 5.4" "$(json "$SRC/examples/.luarc.json" "c['runtime']['version']")"

finish
