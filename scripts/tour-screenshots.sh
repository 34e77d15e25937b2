#!/usr/bin/env bash
# Presents the bundled lecture tour in the real viewer under Xvfb (Mesa's software Vulkan) at 1280x800, steps
# through it with the keys a presenter remote sends (xdotool: Page Down), and captures three steps:
# screenshots/tour-<NN>-<name>.png. The presenter view shows the image, the caption and the probe.
# Needs: xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri imagemagick xdotool (Debian).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=$PWD/target/release/illumlab
runtime=$(mktemp -d); chmod 700 "$runtime"; export XDG_RUNTIME_DIR=$runtime
export XDG_CACHE_HOME=$runtime/cache XDG_CONFIG_HOME=$runtime/config
# step-number:name:seconds to refine before the capture
shots="${SHOTS:-2:cosine-against-uniform:14 9:one-over-r-squared:14 14:path-guiding:40}"
xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
  '$bin' view --tour & pid=\$!
  sleep 6
  win=\$(xdotool search --sync --name '^illumlab\$' | head -1)
  at=1
  for shot in $shots; do
    IFS=: read -r n name wait <<< \"\$shot\"
    while [ \$at -lt \$n ]; do
      xdotool windowfocus --sync \$win key Next
      at=\$((at + 1)); sleep 0.3
    done
    sleep \$wait
    out=screenshots/tour-\$(printf %02d \$n)-\$name.png
    import -window root \$out
    echo \$out
  done
  kill \$pid; wait \$pid 2>/dev/null || true"
