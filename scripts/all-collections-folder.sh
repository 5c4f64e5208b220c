#!/usr/bin/env bash
# Writes every bundled material into one folder of MERL .binary files, for a k-fold run over all
# collections at once (`experiments baselines --mode kfold:5 --data DIR ...`, issue 13):
#
#   scripts/all-collections-folder.sh DIR
#
# the 100 `merl` materials, the 8 of nielsen2015, the 51 RGL NBRDF fits except the 7 whose real
# measurement is bundled (a fit in training while its own measurement is scored would leak), and
# the 7 real RGL measurements converted exactly (`measured-NAME.binary`): 159 materials.
# Set EXPERIMENTS to a built binary to skip `cargo run`.
set -euo pipefail
out="$(realpath -m "${1:?usage: scripts/all-collections-folder.sh DIR}")"
cd "$(dirname "$0")/.."
source scripts/experiments.sh
measured=../shared/data/rgl
mkdir -p "$out/.collections"
for c in merl nielsen2015 rgl; do
    run tabulate --collection "$c" --out "$out/.collections/$c" -q
done
for f in "$out"/.collections/merl/*.binary "$out"/.collections/nielsen2015/*.binary; do
    ln -sf "$(realpath "$f")" "$out/"
done
for f in "$out"/.collections/rgl/*.binary; do
    [[ -f "$measured/$(basename "$f" .binary).bsdf" ]] || ln -sf "$(realpath "$f")" "$out/"
done
for f in "$measured"/*.bsdf; do
    target="$out/measured-$(basename "$f" .bsdf).binary"
    [[ -f "$target" ]] || run convert "$f" -o "$target"
done
echo "$out: $(ls "$out"/*.binary | wc -l) materials"
