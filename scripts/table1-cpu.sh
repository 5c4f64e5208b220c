#!/usr/bin/env bash
# Issue 57: Table 1 trained on the CPU schedule (configs/table1-cpu.json), in-sample on the 100
# `merl` materials, SECONDS more of training per call (default 3000), then PCA, IPCA and the
# model as far as it got, scored with the issue's measures into OUT (default
# results/table1-cpu/in-sample). The model trains in RUNS/in-sample/fold0/k10 (keep RUNS outside
# the repository: it is the run that goes on from session to session); each call resumes it.
# Start it in the background when work on the project starts:
#   nohup scripts/table1-cpu.sh ~/deepbrdf-runs/table1-cpu 3000 > ~/deepbrdf-runs/table1-cpu.log 2>&1 &
# Usage: scripts/table1-cpu.sh RUNS [SECONDS] [OUT]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:?usage: scripts/table1-cpu.sh RUNS [SECONDS] [OUT]}
seconds=${2:-3000}
out=${3:-results/table1-cpu/in-sample}
cargo build --release -p experiments
target/release/experiments baselines --mode in-sample --k 10 --methods pca,ipca,deepbrdf \
    --config configs/table1-cpu.json --models "$runs/in-sample" --time-limit "$seconds" \
    --measures mapped_mse,cos_rmse,image_relae,dark_hole,tinted_centre --out "$out" --force
