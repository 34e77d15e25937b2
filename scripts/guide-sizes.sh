#!/usr/bin/env bash
# The guide's memory and time on every bundled scene: `guided` at 64 spp (all of it training) at each scene's own
# size; prints a markdown table of the last training iteration (spatial leaves, quadtree nodes, KiB, ms to learn
# the iteration's records and to build the guide) and the whole render's time.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/illumlab
out=$(mktemp -d)
echo "| scene | size | records (last iteration) | spatial leaves | quadtree nodes | KiB | learn ms | build ms | mean weights (guide, light, BRDF) | render s (64 spp) |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---|---:|"
for scene in default cornell-box veach-mis near-light occluded-light; do
  log=$($bin render "$scene" --strategy guided --spp 64 -o "$out/x.exr" 2>&1)
  last=$(grep '^guide iteration' <<<"$log" | tail -1)
  # "guide iteration 5: learned from 63 spp (N records, L ms), S spatial leaves, Q quadtree nodes, K KiB, built in
  # B ms, mean weights (guide, light, BRDF) (g, l, b)"
  row=$(sed -E 's/.*\(([0-9]+) records, ([0-9.]+) ms\), ([0-9]+) spatial leaves, ([0-9]+) quadtree nodes, ([0-9.]+) KiB, built in ([0-9.]+) ms, mean weights \(guide, light, BRDF\) (\([0-9., ]+\))/\1 | \3 | \4 | \5 | \2 | \6 | \7/' <<<"$last")
  seconds=$(tail -1 <<<"$log" | sed -E 's/^[0-9]+ spp, ([0-9.]+) s,.*/\1/')
  size=$(grep -E '^(width|height)' "assets/$scene/$scene.toml" | awk '{print $3}' | paste -sd x)
  echo "| $scene | $size | $row | $seconds |"
done
rm -rf "$out"
