#!/usr/bin/env bash
# Renders the README's strategy comparison figures with the real CLI: every strategy at equal samples per pixel
# on each bundled scene, into screenshots/<scene>-<strategy>.png.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/illumlab
spp=${SPP:-16}
for scene in cornell-box veach-mis near-light default; do
  for strategy in $($bin strategies | awk '{print $1}'); do
    exposure=0
    [ "$scene" = cornell-box ] && exposure=1
    [ "$scene" = near-light ] && exposure=-3
    $bin render "$scene" --strategy "$strategy" --spp "$spp" --seed 1 --exposure "$exposure" \
      -o "screenshots/$scene-$strategy.png"
  done
done
