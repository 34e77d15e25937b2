#!/usr/bin/env bash
# Loading a big mesh: writes a rippled grid of 1 002 528 triangles (a 37.7 MB OBJ) and times the whole
# `illumlab render` process on it at 4×4 pixels and 1 spp (so nearly all of it is parsing the OBJ and building the
# BVH), ROUNDS times; prints each run's wall seconds and peak RSS, and the peak RSS per triangle. Each round runs
# three loads, in a cache folder of its own (the tree and OBJ caches, scene::DiskCache, under the script's temporary
# folder): `built` with the caches off, `stored` (read and built, then written to the empty caches) and `read` (the
# OBJ's geometry and the tree read back from them).
# Usage: scripts/load-million.sh [ROUNDS] [BINARY ...]   (default 5, target/release/illumlab; several binaries
# run in turn, round by round)
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
shift || true
binaries=("$@")
if [ ${#binaries[@]} -eq 0 ]; then
  cargo build --release --quiet
  binaries=("$PWD/target/release/illumlab")
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$work/million.obj" <<'EOF'
import math, sys
n = 708  # 2·708² = 1 002 528 triangles
with open(sys.argv[1], "w") as f:
    f.write("# rippled grid\n")
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = i / n * 2 - 1, j / n * 2 - 1
            f.write(f"v {x:.6f} {0.05 * math.sin(20 * x) * math.cos(17 * z):.6f} {z:.6f}\n")
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            b, c, d = a + 1, a + n + 1, a + n + 2
            f.write(f"f {a} {b} {d}\nf {a} {d} {c}\n")
EOF
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; OBJ $(du -m "$work/million.obj" | cut -f1) MB"
for r in $(seq "$rounds"); do
  for b in "${binaries[@]}"; do
    rm -rf "$work/cache"
    for load in built stored read; do
      cache=on
      [ "$load" = built ] && cache=off
      ILLUMLAB_CACHE=$cache XDG_CACHE_HOME="$work/cache" /usr/bin/time -f "%e %M" -o "$work/time" \
        "$b" render "$work/million.obj" --strategy emitter --spp 1 --size 4x4 -o "$work/out.exr" >/dev/null 2>&1
      read -r seconds kb <"$work/time"
      echo "$b round $r, $load: $seconds s, peak RSS $((kb / 1024)) MiB ($((kb * 1024 / 1002528)) bytes per triangle)"
    done
  done
done
