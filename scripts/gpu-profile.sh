#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (after `scripts/gpu-run.sh` has unpacked the libraries, or on
# its own: it unpacks them the same way), from the root of the tracked tree with the bundle of
# `scripts/gpu-bundle.sh` beside it (docs/gpu.md):
#
#   scripts/gpu-profile.sh BUNDLE OUT [PRESET [BATCH]]
#
# One profile of Burn's training step: `experiments bench model` (2 steps, batch BATCH,
# default 32) with CubeCL's kernel profiler on (CUBECL_DEBUG_OPTION=profile), its log
# compressed to OUT/cubecl-profile.log.gz and summed per kernel in OUT/profile-summary.txt
# (scripts/cubecl-profile-summary.py); and PyTorch's Table 1 on the same GPU in strict
# f32 (TF32 off for convolutions and matrix products) and its default (TF32 on), in
# OUT/torch-f32.txt (scripts/torch-bench.py). CONV (default gemm) picks how Burn computes the
# convolutions.
set -uo pipefail
bundle="$(realpath "$1")"
out="$(realpath -m "$2")"
preset="${3:-paper}"
batch="${4:-32}"
cd "$(dirname "$0")/.."
mkdir -p "$out"
exec > >(tee -a "$out/profile.log") 2>&1
for f in "$bundle"/debs/*.deb; do
    package="$(basename "$f" | cut -d_ -f1)"
    dpkg -s "$package" >/dev/null 2>&1 || dpkg -x "$f" /
done
ldconfig
bin=/tmp/deepbrdf-gpu/experiments
if [[ ! -x "$bin" ]]; then
    mkdir -p "$(dirname "$bin")"
    python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' \
        "$bundle/experiments.xz" "$bin"
    chmod +x "$bin"
fi

echo "== Burn, $preset, batch $batch, CubeCL profiler on"
CUBECL_DEBUG_LOG=/tmp/cubecl-profile.log CUBECL_DEBUG_OPTION=profile \
    timeout 150 "$bin" --device wgpu bench model --preset "$preset" --batch "$batch" --steps 2 --decodes 2 \
        --conv "${CONV:-gemm}"
gzip -c /tmp/cubecl-profile.log >"$out/cubecl-profile.log.gz"
python3 scripts/cubecl-profile-summary.py /tmp/cubecl-profile.log | tee "$out/profile-summary.txt"

if [[ -f "$bundle/torch_table1.py" ]]; then
    timeout 150 python3 scripts/torch-bench.py "$bundle/torch_table1.py" "1,$batch" 2>&1 | tee "$out/torch-f32.txt"
fi
