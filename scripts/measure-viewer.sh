#!/usr/bin/env bash
# Measures the real viewer under Xvfb on the Cornell box at 512x512: time from a strategy key (1-4) to the first
# frame of the new strategy on screen, UI frame times while rendering, resident memory, and the viewer's
# throughput against `illumlab render`'s in the same run (10 s of `emitter` after the last toggle, read from the
# screenshot's sidecar: samples over the passes' seconds, and over the wall-clock time since the key press).
# Needs: xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri xdotool jq (Debian).
# BIN=path/to/illumlab measures another build (e.g. an earlier commit's); extra arguments go to `illumlab view`
# (e.g. --threads 2).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${BIN:-}" ]; then
  cargo build --release --quiet
  BIN=$PWD/target/release/illumlab
fi
runtime=$(mktemp -d); chmod 700 "$runtime"; export XDG_RUNTIME_DIR=$runtime
work=$(mktemp -d)
log=$work/trace.log
extra="$*"
(cd "$work" && xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
  ILLUMLAB_TRACE=1 '$BIN' view cornell-box --size 512x512 $extra 2> '$log' & pid=\$!
  sleep 4
  win=\$(xdotool search --sync --name illumlab | head -1)
  xdotool windowfocus --sync \$win 2>/dev/null || true
  for round in 1 2 3 4 5; do
    for key in 2 3 1 4; do xdotool key \$key; sleep 1; done
  done
  date +%s.%N > toggled
  sleep 10
  date +%s.%N > shot
  xdotool key s
  sleep 2
  grep VmHWM /proc/\$pid/status
  grep VmRSS /proc/\$pid/status
  kill \$pid; wait \$pid 2>/dev/null || true")
grep 'restart-to-frame' "$log" | tail -n +2 | awk '{print $3}' | sort -n |
  awk '{v[NR]=$1} END {printf "strategy toggle to frame, %d toggles: median %.1f ms, min %.1f, max %.1f\n", NR, v[int((NR+1)/2)], v[1], v[NR]}'
grep 'ui-frame' "$log" | awk '{print $4}' | sort -n |
  awk '{v[NR]=$1} END {printf "UI frame time while rendering (median of 120-frame medians): %.2f ms over %d windows\n", v[int((NR+1)/2)], NR}'
grep 'ui-frame' "$log" | awk '{print $7}' | sort -n | tail -1 | xargs printf "UI frame time, worst frame: %s ms\n"
grep 'frame-interval' "$log" | awk '{print $4, $7}' | sort -n |
  awk '{v[NR]=$1; m[NR]=$2} END {printf "interval between UI frames (painting included): median %.1f ms, fastest %.1f ms\n", v[int((NR+1)/2)], m[1]}'
sidecar=$(ls -t "$work"/screenshots/*.json | head -1)
wall=$(echo "$(cat "$work/shot") - $(cat "$work/toggled")" | bc)
jq -r --argjson wall "$wall" '"viewer: \(.strategy), \(.spp) spp in \(.passes) passes, \(.samples) samples in \(.seconds|.*1000|floor/1000) s of passes: \(.samples/.seconds/1e6|.*100|floor/100) M samples/s (over \($wall|.*10|floor/10) s wall since the key: \(.samples/$wall/1e6|.*100|floor/100) M/s)"' "$sidecar"
"$BIN" render cornell-box --size 512x512 --strategy emitter --spp 256 -o "$work/render.exr" 2>&1 | tail -1 | sed 's/^/illumlab render, same run: /'
rm -rf "$work"
