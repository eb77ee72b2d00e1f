#!/usr/bin/env bash
# The peer bench: the sphere workload (bench/scenes/sphere_*.ron: N small additive
# particles in a 1 m sphere, 2 s lives, gravity and drag, 3 px at 1920×1080) in ignis, on
# each of its draw paths, and in bevy_hanabi (crates/bench_hanabi), on one GPU in one go;
# then bench/results/peers-<adapter>.md with the ratio per N and path and the images.
#
#   cargo build --release && cargo build --release -p bench_hanabi && scripts/peers.sh
#
# IGNIS, HANABI: the binaries (default target/release/…); OUT: where results go.
set -euo pipefail
cd "$(dirname "$0")/.."
IGNIS=${IGNIS:-target/release/ignis}
HANABI=${HANABI:-target/release/bench_hanabi}
OUT=${OUT:-bench/results/peers}
mkdir -p "$OUT"
declare -A SCENES=([1048576]=sphere_1m [4194304]=sphere_4m [16777216]=sphere_16m)
COUNTS=${COUNTS:-1048576,4194304,16777216}

"$HANABI" --counts "$COUNTS" --out "$OUT"
files=()
for n in ${COUNTS//,/ }; do
    scene=bench/scenes/${SCENES[$n]}.ron
    files+=("$scene")
    # The same frame as the bench times (past the 2 s lives), on ignis's automatic path.
    "$IGNIS" render "$scene" --frames 150 --last-only --size 1920x1080 --out "$OUT/ignis-$n"
    mv "$OUT/ignis-$n/frame_0149.png" "$OUT/ignis-$n.png" && rmdir "$OUT/ignis-$n"
done
"$IGNIS" bench presets "${files[@]}" --sizes 1920x1080 --passes 3 --frames 30 \
    --out "$OUT" --name ignis-spheres
python3 scripts/peers_report.py "$OUT"
