#!/usr/bin/env bash
# Soak: every strategy on every bundled scene, ≥ 10⁹ samples in all, counting non-finite samples (which the
# renderer drops and reports; the goal is zero). Not part of `cargo test`: it takes minutes. Prints a markdown
# table and the totals; exits non-zero if any sample was non-finite.
#   scripts/soak.sh [SPP] [SIZE]    (default 512 spp at 256x256: 4 scenes × 8 strategies × 3.4·10⁷ = 1.07·10⁹)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/illumlab
spp=${1:-512}
size=${2:-256x256}
out=$(mktemp -d)
total=0
bad=0
echo "| scene | strategy | samples | non-finite | seconds |"
echo "|---|---|---:|---:|---:|"
for scene in default cornell-box veach-mis near-light occluded-light; do
  for strategy in $($bin strategies | awk '{print $1}'); do
    line=$($bin render "$scene" --strategy "$strategy" --spp "$spp" --size "$size" --seed 7 -o "$out/x.exr" 2>&1 | tail -1)
    # "512 spp, 4.2 s, 8.0 M samples/s, …, 0 non-finite samples dropped -> …"
    seconds=$(sed -E 's/^[0-9]+ spp, ([0-9.]+) s,.*/\1/' <<<"$line")
    nonfinite=$(sed -E 's/.* ([0-9]+) non-finite samples dropped.*/\1/' <<<"$line")
    w=${size%x*}; h=${size#*x}
    samples=$((w * h * spp))
    total=$((total + samples))
    bad=$((bad + nonfinite))
    echo "| $scene | $strategy | $samples | $nonfinite | $seconds |"
  done
done
rm -rf "$out"
echo
echo "total: $total samples, $bad non-finite ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) threads)"
[ "$bad" -eq 0 ]
