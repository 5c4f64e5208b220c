#!/usr/bin/env bash
# Builds what a GPU machine without Rust or network needs beside the tracked tree
# (docs/gpu.md):
#
#   scripts/gpu-bundle.sh [BUNDLE]        # BUNDLE: default .gpu (git-ignored)
#
# - BUNDLE/experiments.xz: `experiments` built with `--features vulkan` (wgpu, with the SPIR-V
#   compiler on Vulkan; flex as the default CPU backend), stripped and xz-compressed. The
#   bundled materials are inside the binary.
# - BUNDLE/debs/: the Vulkan loader and the GL dispatch libraries NVIDIA's Vulkan driver links
#   against (Debian's libvulkan1, libglvnd0, libglx0, libgl1, libegl1, libopengl0, libgles2;
#   amd64), for a machine whose driver ships without them; `scripts/gpu-run.sh` unpacks each
#   only where it is not installed.
# - BUNDLE/torch_table1.py: the PyTorch Table 1 of ../shared/bench, when that folder exists
#   (for the Burn-beside-PyTorch timing).
#
# It prints the bundle's size and the size of what travels with it (tracked files and
# untracked files git does not ignore), on disk (whole blocks, as the device machine's limit
# counts them), and fails when the two together pass 64 MiB, that limit. Set CARGO_TARGET_DIR to reuse a build (default target-gpu).
set -euo pipefail
cd "$(dirname "$0")/.."
bundle="${1:-.gpu}"
target="${CARGO_TARGET_DIR:-target-gpu}"
limit=$((64 * 1024 * 1024))

echo "building experiments --features vulkan into $target (a clean release build takes ~10 min on 2 cores)"
CARGO_TARGET_DIR="$target" cargo build --release --locked -p experiments --features vulkan
mkdir -p "$bundle/debs"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
strip -o "$tmp/experiments" "$target/release/experiments"
# The x86 filter and a dictionary as large as the binary: 15 MiB instead of 17 at -6.
xz -T1 --x86 --lzma2=preset=9e,dict=128MiB -c "$tmp/experiments" >"$bundle/experiments.xz.tmp"
mv "$bundle/experiments.xz.tmp" "$bundle/experiments.xz"

if ! ls "$bundle"/debs/libglvnd0_*.deb >/dev/null 2>&1; then
    # Debian's package for amd64 whatever this machine is, with a private package list.
    lists="$tmp/lists"
    mkdir -p "$lists/partial"
    apt_opts=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
    apt-get "${apt_opts[@]}" update -qq
    (cd "$bundle/debs" && apt-get "${apt_opts[@]}" download libvulkan1 libglvnd0 libglx0 libgl1 libegl1 libopengl0 libgles2 2>&1 | grep -v unsandboxed || true)
    ls "$bundle"/debs/libvulkan1_*.deb "$bundle"/debs/libglvnd0_*.deb >/dev/null
fi
if [[ -f ../shared/bench/torch_table1.py ]]; then
    cp ../shared/bench/torch_table1.py "$bundle/"
fi

bundle_bytes=$(du -c -B1 "$bundle" | tail -1 | cut -f1)
tree_bytes=$(git ls-files -z --cached --others --exclude-standard | xargs -0 du -c -B1 2>/dev/null \
    | awk '$2 == "total" { s += $1 } END { print s + 0 }') || true # du names deleted files
mib() { awk -v b="$1" 'BEGIN { printf "%.1f MiB", b / 1048576 }'; }
echo "bundle $bundle: $(mib "$bundle_bytes") (binary $(mib "$(stat -c %s "$bundle/experiments.xz")") compressed)"
echo "tree that travels: $(mib "$tree_bytes"); together $(mib $((bundle_bytes + tree_bytes))) of 64 MiB"
if ((bundle_bytes + tree_bytes > limit)); then
    echo "error: the tree and the bundle pass the device machine's 64 MiB" >&2
    exit 1
fi
