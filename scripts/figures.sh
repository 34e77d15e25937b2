#!/usr/bin/env bash
# Renders the README's strategy comparison figures with the real CLI: every strategy at equal samples per pixel
# on each bundled scene, into screenshots/<scene>-<strategy>.png.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/illumlab
spp=${SPP:-16}
for scene in cornell-box veach-mis near-light occluded-light default; do
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
# The glossy ramps of `default` at equal spp (README, "brdf-polygon"): today's best MIS against BRDF-weighted polygon
# sampling with the power and the lobe-aware contribution light selection, cropped to the four slabs.
ramps() { # name args…
  local name=$1; shift
  $bin render default --spp 16 --seed 1 "$@" -o "/tmp/ramps-$name.png"
  convert "/tmp/ramps-$name.png" -crop 480x130+0+160 +repage "screenshots/ramps-$name.png"
}
ramps mis --strategy mis --mis-light projected-solid-angle --light-selection contribution
ramps brdf-polygon-power --strategy brdf-polygon --light-selection power
ramps brdf-polygon-contribution --strategy brdf-polygon --light-selection contribution
ramps mis-brdf-polygon --strategy mis --mis-light brdf-polygon --light-selection contribution
