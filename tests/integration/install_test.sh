# Installed and packaged as a user gets it (docs/install.md): `cmake --install` to a temporary
# prefix, and the Debian package that `./dev package` builds (CPack), unpacked; each runs the
# grand prix from its own share/pitwall with the source and build trees out of reach — hidden
# under an empty tmpfs in a mount namespace of its own (unshare -m), or, where that is not
# allowed, by checking that no path of theirs is compiled into the binary.
source "$(dirname "$0")/lib.sh"
BUILD=$(cd "$(dirname "$PITWALL")" && pwd)
unset PITWALL_DATA PITWALL_SCRIPTS PITWALL_VIEW_DIR PITWALL_PRINT_MODULE

# hidden CMD…: CMD with $SRC and $BUILD hidden (when the mount namespace allows it), from $TMP.
if unshare -m true 2>/dev/null; then
  hidden() {
    unshare -m bash -c 'mount -t tmpfs none "$1" && mount -t tmpfs none "$2" 2>/dev/null; shift 2; cd /tmp && exec "$@"' \
      hide "$SRC" "$BUILD" "$@"
  }
  left=$(hidden sh -c 'ls -A "$1"; [ -e "$2/pitwall" ] && echo "$2/pitwall"' hide "$SRC" "$BUILD")
  check "the source tree ($SRC) and the build tree are hidden while the installed copies run" \
    "" "$left"
else
  hidden() { (cd "$TMP" && "$@"); }
  echo "note: no mount namespace here; the trees stay visible, the binary is checked for their paths"
fi

# runs_from NAME BIN DATA: the installed binary finds its data beside it and races from it.
runs_from() {
  local name=$1 bin=$2 data=$3 out rc
  if grep -qaF "$SRC/scripts" "$bin" || grep -qaF "$BUILD/share" "$bin"; then
    fail "$name: the binary holds a path of the source or build tree"
  else
    echo "ok: $name: no path of the source or build tree is compiled in"
  fi
  out=$(hidden "$bin" --version 2>&1)
  contains "$name: --version names the data folder beside the binary" "data: $data" "$out"
  out=$(hidden "$bin" run "$data/examples/grand_prix.lua" --fast 2>&1); rc=$?
  check "$name: the grand prix runs (exit status)" 0 "$rc"
  contains "$name: the grand prix has a winner" "Winner: " "$out"
  out=$(hidden "$bin" run "$data/examples/hello.lua" --fast --cars 1 2>&1); rc=$?
  check "$name: hello.lua runs" 0 "$rc"
  # the print module, loaded only by track print/verify, is found beside the binary too
  out=$(hidden sh -c 'cd "$2" && "$1" track print S:60,len=300 --out p.svg && "$1" track verify p.svg' \
    hide "$bin" "$TMP" 2>&1); rc=$?
  check "$name: track print and verify run (exit status)" 0 "$rc"
  contains "$name: track verify reads the print back" "all decode to the design" "$out"
  for f in scripts/pitwall/core.lua scripts/pitwall/race.lua examples/.luarc.json web/index.html \
      web/vendor/pitwall-editor.js web/vendor/pitwall-completions.json \
      web/code.html web/code.js examples/classroom/race.lua examples/classroom/starter.lua \
      types/pitwall.lua; do
    [ -f "$data/$f" ] && echo "ok: $name: share/pitwall/$f" || fail "$name: share/pitwall/$f is missing"
  done
  # the code page's classroom: the shipped race and starter are found from the installed data
  rm -rf "$TMP/lesson"
  out=$(hidden "$bin" run --code "$TMP/lesson" --view 127.0.0.1:0 --cars 1 --duration 2 2>&1); rc=$?
  check "$name: run --code (exit status)" 0 "$rc"
  contains "$name: run --code prints the students' address" "code: students open http://127.0.0.1:" "$out"
  contains "$name: the desk starts from the shipped starter" "function driver:update" \
    "$(cat "$TMP/lesson/car-1/driver.lua" 2>/dev/null)"
  # Moved elsewhere, it still runs: nothing points back to where it was installed.
  rm -rf "$TMP/moved" && mkdir -p "$TMP/moved" && cp -a "$(dirname "$(dirname "$bin")")/." "$TMP/moved/"
  out=$(hidden "$TMP/moved/bin/pitwall" run "$TMP/moved/share/pitwall/examples/hello.lua" --fast --cars 1 2>&1); rc=$?
  check "$name: moved to another folder, it still runs" 0 "$rc"
}

# 1. cmake --install to a temporary prefix
if cmake --install "$BUILD" --prefix "$TMP/prefix" >"$TMP/install.log" 2>&1; then
  echo "ok: cmake --install"
  for f in bin/pitwall lib/pitwall/pitwall_print.so share/man/man1/pitwall.1.gz share/bash-completion/completions/pitwall \
      share/zsh/vendor-completions/_pitwall share/doc/pitwall/README.md share/doc/pitwall/docs/install.md; do
    [ -f "$TMP/prefix/$f" ] && echo "ok: installs $f" || fail "cmake --install left out $f"
  done
  runs_from "installed" "$TMP/prefix/bin/pitwall" "$TMP/prefix/share/pitwall"
else
  fail "cmake --install: $(tail -5 "$TMP/install.log")"
fi

# 2. the Debian package, as `./dev package` makes it
if (cd "$BUILD" && cpack -G DEB -B "$TMP/pkg" >"$TMP/cpack.log" 2>&1); then
  deb=$(ls "$TMP"/pkg/pitwall_*.deb 2>/dev/null | head -1)
  version=$("$PITWALL" --version | head -1 | awk '{print $2}')
  check "the package's file name" "pitwall_${version}_$(dpkg --print-architecture).deb" "$(basename "${deb:-none}")"
  depends=$(dpkg-deb -f "$deb" Depends)
  for lib in liblua5.4-0 libsdbus-c++1 libmosquitto1 libreadline8 libevdev2 libcairo2 librsvg2-2; do
    contains "the package depends on $lib (dpkg-shlibdeps)" "$lib" "$depends"
  done
  # Its dependencies are met here as on any Debian 12 with them installed: dpkg would install it.
  out=$(dpkg --dry-run -i "$deb" 2>&1); rc=$?
  check "dpkg --dry-run -i takes the package" 0 "$rc"
  [ "$rc" -eq 0 ] || echo "$out"
  dpkg-deb -x "$deb" "$TMP/deb"
  runs_from "the .deb" "$TMP/deb/usr/bin/pitwall" "$TMP/deb/usr/share/pitwall"
  listing=$(dpkg-deb -c "$deb")
  contains "the package has the man page" "./usr/share/man/man1/pitwall.1.gz" "$listing"
  contains "the package has bash completion" "./usr/share/bash-completion/completions/pitwall" "$listing"
  contains "the package has the print module" "./usr/lib/pitwall/pitwall_print.so" "$listing"
else
  fail "cpack: $(tail -20 "$TMP/cpack.log")"
fi
finish
