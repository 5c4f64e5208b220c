#!/usr/bin/env bash
# Prints the dependencies whose features differ between the Python module's build (maturin
# builds the deepbrdf-python package alone) and the workspace's test build (`cargo test
# --release --workspace --features deepbrdf-model/ndarray`), and fails if there is any: each one
# makes the Python build compile the crates above it (Burn among them) a second time instead of
# reusing the test build's. The pins in python/Cargo.toml keep the list empty.
set -euo pipefail
cd "$(dirname "$0")/.."
features() {
    cargo tree "$@" --prefix none --format '{p} [{f}]' | sed 's/ (\*)//; s/ (proc-macro)//'
}
features -p deepbrdf-python -e normal,build > "${TMPDIR:-/tmp}/deepbrdf-python-features.txt"
features --workspace --features deepbrdf-model/ndarray -e normal,build,dev \
    > "${TMPDIR:-/tmp}/deepbrdf-test-features.txt"
python3 - "${TMPDIR:-/tmp}/deepbrdf-python-features.txt" "${TMPDIR:-/tmp}/deepbrdf-test-features.txt" <<'PY'
import collections
import sys


def load(path):
    """package version -> the feature lists it is built with (one per host/target instance)."""
    seen = collections.defaultdict(set)
    for line in open(path):
        if "[" in line:
            name, version = line.split()[:2]
            seen[f"{name} {version}"].add(line.split("[", 1)[1].rsplit("]", 1)[0])
    return seen


python_build, test_build = load(sys.argv[1]), load(sys.argv[2])
differ = [k for k in sorted(python_build) if python_build[k] != test_build.get(k)]
for k in differ:
    print(f"{k}: python build {sorted(python_build[k])}, test build {sorted(test_build.get(k, []))}")
if differ:
    sys.exit("features differ between the Python module's build and the test build (above)")
print("the Python module's build resolves every dependency's features as the test build does")
PY
