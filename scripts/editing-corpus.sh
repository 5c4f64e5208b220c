#!/usr/bin/env bash
# Does a generated corpus make edits do what they ask? One fold of `merl` (fold 0 of kfold:5),
# a `slice` model at k = 10 trained on the other 80 materials alone and one per corpus size N
# with the first N materials of a corpus streamed beside them (`train --corpus`), each with its
# regressors (`train-regressor --ipca`, with the first NR corpus materials for N > 0); then for
# each model the edits against known answers (`edit-known`, 70 corpus materials of another seed,
# so none was trained on) and the editing suite on the 20 held-out `merl` materials
# (`figures-editing`):
#
#   scripts/editing-corpus.sh [WORK [N...]]     # WORK default runs/editing-corpus; N default 0 3000
#
# Writes WORK/corpus-N/{known,heldout}/results.md and copies them into
# results/editing-corpus/corpus-N/. NR (default 1000) bounds the regressor's corpus materials.
# HELD_PASSES=P (default 1) trains with P passes over the measured materials per epoch against
# one over the corpus (`train --held-passes`), into corpus-N-heldP. REGRESSOR_ONLY=1 gives the
# corpus to the regressor alone (the autoencoder trains on the measured materials), into
# corpus-N-regressor: which of the two networks the corpus helps.
# Every step resumes: run it again after an interruption. Set EXPERIMENTS to a built binary to
# skip `cargo run`.
set -euo pipefail
work="$(realpath -m "${1:-$(dirname "$0")/../runs/editing-corpus}")"
shift || true
sizes=(0 3000)
[[ $# -gt 0 ]] && sizes=("$@")
nr="${NR:-1000}"
passes="${HELD_PASSES:-1}"
suffix=""
(( passes > 1 )) && suffix="-held$passes"
regressor_only="${REGRESSOR_ONLY:-0}"
(( regressor_only == 1 )) && suffix="$suffix-regressor"
cd "$(dirname "$0")/.."
source scripts/experiments.sh
mkdir -p "$work"
[[ -d "$work/merl" ]] || run tabulate --collection merl --out "$work/merl" -q
run folds --fold 0 > "$work/fold0.txt"
mkdir -p "$work/merl20" "$work/merl80"
for f in "$work"/merl/*.binary; do
    if grep -qx "$(basename "$f" .binary)" "$work/fold0.txt"; then
        ln -sf "$f" "$work/merl20/"
    else
        ln -sf "$f" "$work/merl80/"
    fi
done
largest=0
for n in "${sizes[@]}"; do (( n > largest )) && largest=$n; done
if (( largest > 0 )) && [[ ! -f "$work/corpus/corpus.jsonl" ]]; then
    run corpus --count "$largest" --seed 0 --out "$work/corpus" -q
fi
for n in "${sizes[@]}"; do
    dir="$work/corpus-$n$suffix"
    corpus=()
    regressor_corpus=()
    if (( n > 0 )); then
        (( regressor_only == 1 )) || corpus=(--corpus "$work/corpus/corpus.jsonl" --corpus-count "$n")
        regressor_corpus=(--corpus "$work/corpus/corpus.jsonl" --corpus-count "$(( nr < n ? nr : n ))")
    fi
    if [[ ! -f "$dir/model/model/model.json" ]]; then
        if [[ -f "$dir/model/checkpoint.bin" ]]; then
            run train --resume "$dir/model" -q
        else
            run train --preset slice --k 10 --data "$work/merl80" "${corpus[@]}" --held-passes "$passes" \
                --out "$dir/model" -q
        fi
    fi
    [[ -d "$dir/regressor" ]] || run train-regressor --model "$dir/model" --data "$work/merl80" \
        "${regressor_corpus[@]}" --ipca --out "$dir/regressor" -q
    [[ -f "$dir/known/results.md" ]] || run edit-known --model "$dir/model" --regressor "$dir/regressor" \
        --count 70 --methods analytic,deepbrdf-residual,deepbrdf-transfer --out "$dir/known" -q
    [[ -f "$dir/heldout/results.md" ]] || run figures-editing --model "$dir/model" \
        --regressor "$dir/regressor" --data "$work/merl20" --every 1 --no-figures --out "$dir/heldout" -q
    results="results/editing-corpus/$(basename "$dir")"
    mkdir -p "$results/known" "$results/heldout"
    cp "$dir/known/results.md" "$dir/known/known.csv" "$results/known/"
    cp "$dir/heldout/results.md" "$dir/heldout/suite.csv" "$results/heldout/"
done
echo "results in results/editing-corpus"
