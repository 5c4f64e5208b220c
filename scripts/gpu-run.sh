#!/usr/bin/env bash
# Runs on a machine with a GPU, no Rust and no network, from the root of the tracked tree with
# the bundle of `scripts/gpu-bundle.sh` beside it (docs/gpu.md):
#
#   scripts/gpu-run.sh BUNDLE OUT SECONDS [PRESET [K [DEVICE]]]
#
# Unpacks the binary (and the Vulkan loader where the machine has none), then, all within
# SECONDS of wall time:
# 1. `experiments bench model --preset PRESET` on DEVICE (training step and decode times),
#    and, where BUNDLE/torch_table1.py and a CUDA PyTorch exist, the same network in PyTorch on
#    the same GPU (BENCH=0 skips both);
# 2. PRESET (default paper) at K (default 10) trained on the 100 bundled `merl` materials
#    through `experiments baselines --mode in-sample --methods deepbrdf,pca,ipca` with
#    `--time-limit`:
#    training stops at the end of the first epoch past what the budget leaves after a reserve
#    for the evaluation (EVAL_RESERVE seconds, default 200, which also covers tabulating the materials), and the model is scored with the
#    measures of `sweep-k` (mapped MSE, cosine-weighted RMSE, image RelAE). Models and
#    checkpoints go to RUNS (default runs/gpu-PRESET-kK): run the same command again on the same
#    machine and training resumes from the checkpoint.
# DEVICE defaults to wgpu (Vulkan on an NVIDIA GPU; `--device flex` checks the script on a CPU).
# DATA_ARGS replaces `--collection merl` (e.g. `--collection nielsen2015`, 8 materials, for a
# check on a CPU). OUT receives run.log (everything printed, with nvidia-smi samples), bench.txt, torch.txt and
# results.tar.gz (the results folder, the training log and configuration; no weights).
set -uo pipefail
started=$(date +%s)
bundle="$(realpath "$1")"
out="$(realpath -m "$2")"
budget="$3"
preset="${4:-paper}"
k="${5:-10}"
device="${6:-wgpu}"
reserve="${EVAL_RESERVE:-200}"
runs="$(realpath -m "${RUNS:-runs/gpu-$preset-k$k}")"
cd "$(dirname "$0")/.."
mkdir -p "$out" "$runs"
log="$out/run.log"
exec > >(tee -a "$log") 2>&1
left() { echo $((budget - ($(date +%s) - started))); }
say() { echo "[gpu-run +$(($(date +%s) - started))s] $*"; }

# The Vulkan loader and the GL vendor-neutral dispatch libraries that NVIDIA's Vulkan driver
# (libGLX_nvidia) links against, where the image lacks them.
unpacked=0
for f in "$bundle"/debs/*.deb; do
    package="$(basename "$f" | cut -d_ -f1)"
    if ! dpkg -s "$package" >/dev/null 2>&1; then
        dpkg -x "$f" / && unpacked=$((unpacked + 1))
    fi
done
((unpacked > 0)) && { say "unpacked $unpacked bundled libraries"; ldconfig; }
if [[ -z "${VK_DRIVER_FILES:-}" && -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]] \
    && ! ls /usr/share/vulkan/icd.d/nvidia_icd*.json /etc/vulkan/icd.d/nvidia_icd*.json >/dev/null 2>&1; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
bin=/tmp/deepbrdf-gpu/experiments
mkdir -p "$(dirname "$bin")"
if command -v xz >/dev/null; then
    xz -dc "$bundle/experiments.xz" >"$bin"
else
    python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' \
        "$bundle/experiments.xz" "$bin"
fi
chmod +x "$bin" || { say "cannot unpack the binary"; exit 1; }
say "binary: $("$bin" --version 2>&1 | head -1); devices:"
"$bin" devices
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
export RUST_BACKTRACE=1
# A one-step smoke test first, so a binary the driver cannot run costs seconds, not the budget.
say "smoke test: one training step and one decode on $device"
timeout 120 "$bin" --device "$device" bench model --preset "$preset" --k "$k" --batch 1 --steps 1 --decodes 1
smoke=$?
if ((smoke != 0)); then
    say "the smoke test failed (exit $smoke): stopping"
    exit "$smoke"
fi

if [[ "${BENCH:-1}" == 1 ]]; then
    say "bench: experiments bench model --preset $preset --device $device"
    timeout 150 "$bin" --device "$device" bench model --preset "$preset" --k "$k" --steps 6 --decodes 6 \
        2>&1 | tee "$out/bench.txt"
    py=python3
    if [[ -f "$bundle/torch_table1.py" ]] && "$py" -c 'import torch, sys; sys.exit(0 if torch.cuda.is_available() else 1)' 2>/dev/null; then
        say "bench: PyTorch Table 1 on the same GPU"
        {
            timeout 90 "$py" "$bundle/torch_table1.py" --device cuda --mode train --batch 1,32 --steps 12
            timeout 60 "$py" "$bundle/torch_table1.py" --device cuda --mode decode --steps 20
        } 2>&1 | tee "$out/torch.txt"
    else
        say "bench: no CUDA PyTorch here (or no torch_table1.py in the bundle): PyTorch not timed"
    fi
fi

train_limit=$(($(left) - reserve))
if ((train_limit < 30)); then
    say "only $(left) s left: no training"
else
    if command -v nvidia-smi >/dev/null; then
        nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv,noheader -l 20 \
            >"$out/gpu-usage.csv" 2>&1 &
        smi=$!
    fi
    say "training $preset k = $k on ${DATA_ARGS:-merl} for at most $train_limit s, then the evaluation"
    "$bin" --device "$device" baselines --mode in-sample --k "$k" --methods deepbrdf,pca,ipca \
        --preset "$preset" --refine 0 --time-limit "$train_limit" \
        --measures mapped_mse,cos_rmse,image_relae --models "$runs/models" --out "$runs/results" --force \
        ${DATA_ARGS:---collection merl}
    status=$?
    [[ -n "${smi:-}" ]] && kill "$smi" 2>/dev/null
    say "baselines exited with $status"
    model_dir="$runs/models/fold0/k$k"
    [[ -f "$model_dir/train_log.csv" ]] && { say "epochs trained:"; tail -3 "$model_dir/train_log.csv"; }
    tar -czf "$out/results.tar.gz" -C "$runs" results \
        $(cd "$runs" && ls models/fold0/k"$k"/{train_log.csv,train_config.json,model/model.json} 2>/dev/null)
fi
say "done, $(left) s of the budget left"
