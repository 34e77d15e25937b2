#!/usr/bin/env bash
# Measures the real viewer under Xvfb: time from a strategy key (1-4) to the first frame of the new strategy
# on screen, UI frame times while rendering, and resident memory. Scene cornell-box at 512x512.
# Needs: xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri xdotool (Debian).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
runtime=$(mktemp -d); chmod 700 "$runtime"; export XDG_RUNTIME_DIR=$runtime
log=$(mktemp)
xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
  ILLUMLAB_TRACE=1 '$PWD/target/release/illumlab' view cornell-box --size 512x512 2> '$log' & pid=\$!
  sleep 4
  win=\$(xdotool search --sync --name illumlab | head -1)
  xdotool windowfocus --sync \$win 2>/dev/null || true
  for round in 1 2 3 4 5; do
    for key in 2 3 1 4; do xdotool key \$key; sleep 1; done
  done
  grep VmHWM /proc/\$pid/status
  grep VmRSS /proc/\$pid/status
  kill \$pid; wait \$pid 2>/dev/null || true"
grep 'restart-to-frame' "$log" | tail -n +2 | awk '{print $3}' | sort -n |
  awk '{v[NR]=$1} END {printf "strategy toggle to frame, %d toggles: median %.1f ms, min %.1f, max %.1f\n", NR, v[int((NR+1)/2)], v[1], v[NR]}'
grep 'ui-frame' "$log" | awk '{print $4}' | sort -n |
  awk '{v[NR]=$1} END {printf "UI frame time while rendering (median of 120-frame medians): %.2f ms over %d windows\n", v[int((NR+1)/2)], NR}'
grep 'ui-frame' "$log" | awk '{print $7}' | sort -n | tail -1 | xargs printf "UI frame time, worst frame: %s ms\n"
grep 'frame-interval' "$log" | awk '{print $4, $7}' | sort -n |
  awk '{v[NR]=$1; m[NR]=$2} END {printf "interval between UI frames (painting included): median %.1f ms, fastest %.1f ms\n", v[int((NR+1)/2)], m[1]}'
rm -f "$log"
