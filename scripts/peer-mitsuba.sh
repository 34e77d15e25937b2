#!/usr/bin/env bash
# illumlab against Mitsuba 3 (llvm_ad_rgb, the `direct` integrator) on the same scenes, strategies, size and spp,
# in turn: illumlab's whole `render` process against Mitsuba's warm render (scripts/peer_mitsuba.py says how the
# scenes are made alike). Sets up Mitsuba in a venv (pip `mitsuba`) and Debian's libllvm19 if missing.
# Usage: scripts/peer-mitsuba.sh [SIZE] [SPP] [ROUNDS]   (default 256 256 5)
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${MITSUBA_VENV:-/opt/mitsuba-venv}
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import mitsuba, numpy' 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet mitsuba numpy
fi
llvm=$(ls /usr/lib/x86_64-linux-gnu/libLLVM.so.19* 2>/dev/null | head -1 || true)
if [ -z "$llvm" ]; then
  apt-get install -y -qq libllvm19 >/dev/null
  llvm=$(ls /usr/lib/x86_64-linux-gnu/libLLVM.so.19* | head -1)
fi
export DRJIT_LIBLLVM_PATH=$llvm
cargo build --release --quiet
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores; flags: $(grep -o -w 'avx2\|avx512f' /proc/cpuinfo | sort -u | tr '\n' ' ')"
"$venv/bin/python" scripts/peer_mitsuba.py "$PWD/target/release/illumlab" \
  "assets/cornell-box/cornell-box.toml,assets/knot-box/knot-box.toml" emitter,mis "${1:-256}" "${2:-256}" "${3:-5}"
