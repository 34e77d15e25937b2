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
# The near-light close-ups: 4 spp, exposure −10, where only emitter sampling is grainy around the light.
for strategy in emitter solid-angle projected-solid-angle; do
  $bin render near-light --strategy "$strategy" --spp 4 --seed 1 --exposure -10 -o "screenshots/near-light-closeup-$strategy.png"
done
