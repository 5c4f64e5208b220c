#!/usr/bin/env bash
# Issue 57, goal 2: trains Table 1 under each schedule of configs/table1-schedules/ for the same
# time on the in-sample `merl` set (default: 660 s each, one after another), into
# RUNS/<schedule>/ (a schedule whose run folder exists is skipped: continue one with
# `experiments train --resume RUNS/<schedule>`), then plots every run's loss curves with
# `experiments figures-schedules`. Usage: scripts/table1-schedules.sh RUNS [SECONDS] [PLOT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:?usage: scripts/table1-schedules.sh RUNS [SECONDS] [PLOT_DIR]}
seconds=${2:-660}
plot=${3:-}
exp=target/release/experiments
for config in configs/table1-schedules/*.json; do
    name=$(basename "$config" .json)
    out="$runs/$name"
    if [ -e "$out" ]; then
        echo "== $name: $out exists, skipped"
    else
        echo "== $name: starting"
        "$exp" train --config "$config" --out "$out" --time-limit "$seconds" --quiet || true
    fi
done
if [ -n "$plot" ]; then
    "$exp" figures-schedules "$runs" --out "$plot"
fi
