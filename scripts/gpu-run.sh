#!/usr/bin/env bash
# Runs on a machine with a GPU, no Rust and no network, from the root of the tracked tree with
# the bundle of `scripts/gpu-bundle.sh` beside it (docs/gpu.md):
#
#   scripts/gpu-run.sh BUNDLE OUT SECONDS [PRESET [K [DEVICE]]]
#
# Unpacks the binary (and the Vulkan loader where the machine has none), then, all within
# SECONDS of wall time:
# 1. `experiments bench model --preset PRESET --conv CONV` on DEVICE (training step at the
#    preset's batch and decode times, once per convolution algorithm of CONV, default
#    direct,gemm; BENCH_STEPS timed steps, default 6; BENCH_BATCH instead of the preset's batch),
#    and, where BUNDLE/torch_table1.py and a CUDA PyTorch exist, the same network in
#    PyTorch on the same GPU in strict f32 and with TF32 (scripts/torch-bench.py; BENCH=0 skips
#    both);
# 2. PRESET (default paper) at K (default 10) trained on the 100 bundled `merl` materials
#    through `experiments baselines --mode in-sample --methods deepbrdf,pca,ipca` with
#    `--time-limit`: training stops at the end of the first epoch past its share of what the
#    budget leaves after the evaluations' reserves (EVAL_RESERVE seconds each, default 200,
#    which also covers tabulating the materials; GENERALIZE_RESERVE, default 120), and the
#    model is scored with the measures of `sweep-k` (mapped MSE, cosine-weighted RMSE, image
#    RelAE);
# 3. the same model (resumed for one epoch if unfinished) scored on the seven real RGL
#    measurements it never saw (`--mode generalize --eval-collections rgl-measured`, beside PCA
#    and IPCA fitted on the same materials);
# 4. held out: fold 0 of the main job's 5-fold split (`--mode kfold:5 --fold 0`: 80 trained,
#    20 scored) with the rest of the budget (HELDOUT_SHARE percent of the training time,
#    default 45).
# Models and checkpoints go to RUNS (default runs/gpu-PRESET-kK): run the same command again on
# the same machine and training resumes from the checkpoints.
# DEVICE defaults to wgpu (Vulkan on an NVIDIA GPU; `--device flex` checks the script on a CPU).
# DATA_ARGS replaces `--collection merl` (e.g. `--collection nielsen2015`, 8 materials, for a
# check on a CPU). OUT receives run.log (everything printed, with nvidia-smi samples), bench.txt,
# torch.txt, results.tar.gz (the three results folders, the training logs and configurations)
# and model-in-sample.tar.gz, model-heldout-fold0.tar.gz (the trained models as `train` writes
# them).
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
    [[ -e "$f" ]] || continue
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
    conv="${CONV:-direct,gemm}"
    say "bench: experiments bench model --preset $preset --conv $conv --device $device"
    timeout 200 "$bin" --device "$device" bench model --preset "$preset" --k "$k" --conv "$conv" \
        --steps "${BENCH_STEPS:-6}" --decodes 6 ${BENCH_BATCH:+--batch "$BENCH_BATCH"} 2>&1 | tee "$out/bench.txt"
    py=python3
    if [[ -f "$bundle/torch_table1.py" ]] && "$py" -c 'import torch, sys; sys.exit(0 if torch.cuda.is_available() else 1)' 2>/dev/null; then
        say "bench: PyTorch Table 1 on the same GPU, strict f32 and TF32"
        timeout 150 "$py" scripts/torch-bench.py "$bundle/torch_table1.py" 1,32 2>&1 | tee "$out/torch.txt"
    else
        say "bench: no CUDA PyTorch here (or no torch_table1.py in the bundle): PyTorch not timed"
    fi
fi

generalize_reserve="${GENERALIZE_RESERVE:-120}"
heldout_share="${HELDOUT_SHARE:-45}"
# One `baselines` run of PRESET beside PCA and IPCA: NAME (its folder under RUNS), MODELS (where
# the model trains or is found finished), LIMIT (seconds of training), then the mode's options.
score() {
    local name="$1" models="$2" limit="$3"
    shift 3
    say "$name: $preset k = $k, at most $limit s of training, then the evaluation"
    "$bin" --device "$device" baselines --k "$k" --methods deepbrdf,pca,ipca --preset "$preset" \
        --refine 0 --time-limit "$limit" --measures mapped_mse,cos_rmse,image_relae \
        --models "$models" --out "$runs/$name" --force "$@" ${DATA_ARGS:---collection merl}
    say "$name: baselines exited with $?"
    [[ -f "$models/fold0/k$k/train_log.csv" ]] && { say "$name: epochs trained:"; tail -2 "$models/fold0/k$k/train_log.csv"; }
}
# The training time the budget leaves after the evaluations, split between the in-sample model
# and fold 0's held-out one (HELDOUT_SHARE percent of it, default 45; 0 skips the held-out run).
train_total=$(($(left) - 2 * reserve - generalize_reserve))
if ((train_total < 30)); then
    say "only $(left) s left: no training"
else
    if command -v nvidia-smi >/dev/null; then
        nvidia-smi --query-gpu=timestamp,utilization.gpu,memory.used --format=csv,noheader -l 20 \
            >"$out/gpu-usage.csv" 2>&1 &
        smi=$!
    fi
    # 2. In-sample on every material (the paper's protocol).
    score in-sample "$runs/in-sample" $((train_total * (100 - heldout_share) / 100)) --mode in-sample
    # 3. The same model on the seven real RGL measurements it never saw.
    if (($(left) >= generalize_reserve / 2)) && [[ -d "$runs/in-sample/fold0/k$k/model" ]]; then
        score rgl-measured "$runs/in-sample" 1 --mode generalize --eval-collections rgl-measured
    fi
    # 4. Held out: fold 0 of `baselines --mode kfold:5` (the main job's split), trained on the rest.
    heldout_limit=$(($(left) - reserve))
    if ((heldout_share > 0 && heldout_limit >= 30)); then
        score heldout-fold0 "$runs/heldout-fold0" "$heldout_limit" --mode kfold:5 --fold 0
    fi
    [[ -n "${smi:-}" ]] && kill "$smi" 2>/dev/null
    cd "$runs"
    tar -czf "$out/results.tar.gz" $(ls -d in-sample rgl-measured heldout-fold0 2>/dev/null \
        | xargs -I{} find {} -maxdepth 1 -type f) \
        $(ls in-sample/fold0/k"$k"/{train_log.csv,train_config.json,model/model.json} \
            heldout-fold0/fold0/k"$k"/{train_log.csv,train_config.json,model/model.json} 2>/dev/null)
    for name in in-sample heldout-fold0; do
        [[ -d "$name/fold0/k$k/model" ]] && tar -czf "$out/model-$name.tar.gz" -C "$name/fold0/k$k" model
    done
    cd - >/dev/null
fi
say "done, $(left) s of the budget left"
