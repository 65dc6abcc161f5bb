# The command line's front door (docs/cli.md): --version, bare `pitwall`, a mistyped command or
# option answered with the nearest, the options every command takes after the command too, the
# shell completion scripts (loaded and asked as bash and zsh ask them) and the man page.
source "$(dirname "$0")/lib.sh"

# --version: "pitwall X.Y.Z[ (git …)]", then the libraries, BlueZ, the data folder
out=$($PITWALL --version); rc=$?
check "--version exit status" 0 "$rc"
first=$(echo "$out" | head -1)
if [[ "$first" =~ ^pitwall\ [0-9]+\.[0-9]+\.[0-9]+(\ \(git\ [^\)]+\))?$ ]]; then
  echo "ok: --version's first line: $first"
else
  fail "--version's first line is not 'pitwall X.Y.Z (git …)': [$first]"
fi
version=$(sed -n 's/^project(pitwall VERSION \([0-9.]*\).*/\1/p' "$SRC/CMakeLists.txt")
contains "--version is the project's version" "pitwall $version" "$first"
if git -C "$SRC" rev-parse --git-dir >/dev/null 2>&1; then
  contains "--version has git describe" "(git $(git -C "$SRC" describe --always --tags)" "$first"
fi
if [[ "$(echo "$out" | sed -n 2p)" =~ ^Lua\ 5\.4\.[0-9]+,\ sdbus-c\+\+\ [0-9.]+,\ libmosquitto\ [0-9.]+,\ Boost\ [0-9.]+$ ]]; then
  echo "ok: --version names Lua, sdbus-c++, libmosquitto and Boost"
else
  fail "--version's second line: [$(echo "$out" | sed -n 2p)]"
fi
contains "--version names BlueZ" "BlueZ" "$(echo "$out" | sed -n 3p)"
contains "--version names the data folder" "data: " "$(echo "$out" | sed -n 4p)"

check "--version after a command answers too" "$first" "$($PITWALL run --version | head -1)"
out=$(PITWALL_DATA=/nonexistent $PITWALL --version)
contains "a PITWALL_DATA without data is named, not passed over" "data: not found (PITWALL_DATA=/nonexistent holds no scripts/pitwall/core.lua" "$out"

# bare pitwall: every command with one line
out=$($PITWALL); rc=$?
check "bare pitwall exit status" 0 "$rc"
for c in run repl bridge view scan emulate-car sim-robot test replay track decode encode types completion; do
  if grep -qE "^  $c +[A-Z]" <<< "$out"; then echo "ok: bare pitwall lists $c"; else fail "bare pitwall does not list $c: $out"; fi
done

# mistyped: the nearest, status 2, one line
err=$($PITWALL rn x.lua 2>&1); rc=$?
check "unknown command exit status" 2 "$rc"
check "unknown command suggests run" "pitwall: unknown command 'rn'; did you mean run? (\`pitwall\` lists the commands)" "$err"
err=$($PITWALL --log-level warn tset 2>&1); rc=$?
check "unknown command after an option" "pitwall: unknown command 'tset'; did you mean test? (\`pitwall\` lists the commands)" "$err"
err=$($PITWALL frobnicate 2>&1); rc=$?
check "a word near no command: status" 2 "$rc"
check "a word near no command: no suggestion" "pitwall: unknown command 'frobnicate' (\`pitwall\` lists the commands)" "$err"
err=$($PITWALL run "$SRC/examples/hello.lua" --fsat 2>&1); rc=$?
check "unknown option exit status" 2 "$rc"
check "unknown option suggests --fast" "pitwall run: unknown option --fsat; did you mean --fast? (\`pitwall run --help\` lists the options)" "$err"
err=$($PITWALL track shwo oval 2>&1); rc=$?
check "unknown subcommand suggests show" "pitwall track: unknown command 'shwo'; did you mean show? (\`pitwall track --help\` lists its commands)" "$err"
err=$($PITWALL $'\e[31mred' 2>&1); rc=$?
check "a word with control characters is shown escaped" "pitwall: unknown command '\\x1b[31mred' (\`pitwall\` lists the commands)" "$err"
err=$($PITWALL RUN 2>&1)
check "a case-only slip gets the command" "pitwall: unknown command 'RUN'; did you mean run? (\`pitwall\` lists the commands)" "$err"
err=$($PITWALL --log-level loud 2>&1); rc=$?
check "a bad --log-level without a command: status" 2 "$rc"
err=$($PITWALL run 2>&1); rc=$?
check "a missing argument is still CLI11's word, status 2" 2 "$rc"
contains "a missing argument names it" "script" "$err"

# --log-level and -q after the command
out=$($PITWALL run "$SRC/examples/hello.lua" --fast --cars 1 2>&1)
contains "info lines by default" "] info " "$out"
for q in -q --quiet "--log-level warn" "--log-level=error"; do
  # shellcheck disable=SC2086
  out=$($PITWALL run "$SRC/examples/hello.lua" --fast --cars 1 $q 2>&1); rc=$?
  check "run … $q: exit status" 0 "$rc"
  case "$out" in *"] info "*) fail "run … $q still logs info lines: $out" ;; *) echo "ok: run … $q logs no info line" ;; esac
done
err=$($PITWALL run "$SRC/examples/hello.lua" --log-level loud 2>&1); rc=$?
check "a bad --log-level after the command: status" 2 "$rc"
contains "a bad --log-level names the levels" "use debug, info, warn, error or off" "$err"

# bash: the script loads, registers, and completes what a user types
$PITWALL completion bash >"$TMP/pitwall.bash"
check "bash completion registers" "complete -F _pitwall pitwall" "$(bash -c "source '$TMP/pitwall.bash'; complete -p pitwall")"
mkdir -p "$TMP/proj/races" && touch "$TMP/proj/grand.lua" "$TMP/proj/grid.txt"
ask() {  # ask WORD…: what bash completes for the last word of `WORD…`
  (cd "$TMP/proj" && bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _pitwall; printf "%s\n" "${COMPREPLY[@]}" | sort | xargs' \
    ask "$TMP/pitwall.bash" "$@")
}
check "bash: commands" "repl replay run" "$(ask pitwall r)"
check "bash: a command's options" "--track" "$(ask pitwall run --tr)"
check "bash: options every command takes" "--log-level" "$(ask pitwall run grand.lua --log-)"
check "bash: layout names and files" "grand.lua grid.txt kidney long oval races/" "$(ask pitwall run --track "")"
check "bash: layout names" "oval" "$(ask pitwall track show o)"
check "bash: script files (*.lua) and folders" "grand.lua races/" "$(ask pitwall run "")"
check "bash: after an option's value, the script" "grand.lua" "$(ask pitwall run --seed 3 gr)"
check "bash: log levels" "warn" "$(ask pitwall --log-level w)"
check "bash: the protocol of decode" "anki" "$(ask pitwall decode an)"
check "bash: subcommands" "list print show verify" "$(ask pitwall track "")"
check "bash: the paper of track print" "a3 a4" "$(ask pitwall track print S --paper "")"
check "bash: folders only for types" "races/" "$(ask pitwall types "")"
mkdir -p "$TMP/proj/my races" && touch "$TMP/proj/my file.lua"
ask_lines() {  # one completion per line: names with spaces stay whole
  (cd "$TMP/proj" && bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _pitwall; printf "%s\n" "${COMPREPLY[@]}" | sort' \
    ask "$TMP/pitwall.bash" "$@")
}
check "bash: names with spaces stay whole" "my file.lua
my races/" "$(ask_lines pitwall run my)"

# zsh: loads from fpath with compinit and completes at a real prompt (python3-pexpect)
$PITWALL completion zsh >"$TMP/_pitwall"
if command -v zsh >/dev/null; then
  zsh -n "$TMP/_pitwall" && echo "ok: zsh completion parses" || fail "zsh completion does not parse"
  out=$(/usr/bin/python3 "$SRC/tests/integration/zsh_complete.py" "$TMP" 2>&1); rc=$?
  if [ "$rc" -eq 77 ]; then echo "note: $out"; else check "zsh completes at a prompt" 0 "$rc"; [ "$rc" -eq 0 ] || echo "$out"; fi
else
  fail "zsh is not installed (./dev test installs it)"
fi

# the man page: help2man's, with every command
man=$(dirname "$PITWALL")/share/man/man1/pitwall.1.gz
if [ -f "$man" ]; then
  page=$(zcat "$man")
  contains "the man page has the NAME line" "pitwall \\- an automation engine" "$page"
  contains "the man page has the COMMANDS section" ".SH COMMANDS" "$page"
  contains "the man page has run's options" "--fast" "$page"
  contains "the man page has the environment" "PITWALL_DATA" "$page"
  if command -v man >/dev/null; then
    out=$(MANWIDTH=100 man -l "$man" 2>&1); rc=$?
    check "man -l renders the page" 0 "$rc"
    case "$out" in
      *"???"*) fail "the man page lost characters to '???' (help2man read the help in the C locale)" ;;
      *) echo "ok: the man page keeps every character" ;;
    esac
  fi
else
  fail "no man page at $man (the build makes it with help2man)"
fi
finish
