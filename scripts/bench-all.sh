#!/bin/sh
# Runs `illumlab bench` on every bundled scene (default budgets 1..256 spp, 8 seeds, fixed primary hits, pixels
# that see a light left out, reference at 4096 spp) and writes
# docs/bench/<scene>/{bench.csv,bench.md,convergence.png,convergence-relative.png}, and the verdicts in
# docs/bench/summary.md. Run it on an otherwise idle machine: timings are wall-clock.
set -e
cd "$(dirname "$0")/.."
cargo build --release
for scene in cornell-box near-light veach-mis default; do
    target/release/illumlab bench "$scene" --out "docs/bench/$scene" "$@"
done
# Light through a small hole: MIS resolves it slowly, so the reference is guided's (trained within its samples).
target/release/illumlab bench occluded-light --reference-strategy guided --out docs/bench/occluded-light "$@"
# The references are large and reproducible: keep them out of the repository.
rm -f docs/bench/*/reference.exr docs/bench/*/reference.var.exr
# Every scene's table at the largest budget, with intervals and verdicts (for the README and docs).
python3 scripts/bench-tables.py > /dev/null
