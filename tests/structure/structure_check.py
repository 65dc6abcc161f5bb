"""What every structure check shares: the C++ sources of engine/ and bindings/, read once, and the
run that self-tests the check, applies it and reports each finding on stderr."""
import pathlib
import sys


def sources(root):
    """{path relative to root: text} of every .cpp and .hpp under engine/ and bindings/."""
    files = {}
    for top in ("engine", "bindings"):
        for p in (pathlib.Path(root) / top).rglob("*"):
            if p.suffix in (".cpp", ".hpp"):
                files[str(p.relative_to(root))] = p.read_text(encoding="utf-8", errors="replace")
    return files


def run(name, what, self_test, violations):
    """Self-tests, then checks the sources under argv[1]; 1 when anything was found."""
    self_test()
    files = sources(sys.argv[1])
    found = list(violations(files))
    for v in found:
        print(v, file=sys.stderr)
    print(f"{name}: {len(files)} files, {len(found)} {what}")
    return 1 if found else 0
