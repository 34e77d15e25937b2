#!/usr/bin/env bash
# Runs the real viewer under Xvfb (Mesa's software Vulkan), waits for it to refine, and captures the window:
# screenshots/viewer-<scene>-<strategy>.png for each bundled scene and a few strategies, and compare mode
# (screenshots/viewer-compare-*.png; references are rendered into a temporary cache).
# Needs: xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri imagemagick (Debian).
# With an argument, takes only the screenshots whose file name contains it (e.g. `occluded-light`).
set -euo pipefail
only=${1:-}
wanted() { [[ -z $only || $1 == *"$only"* ]]; }
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=$PWD/target/release/illumlab
wait_s=${WAIT:-12}
runtime=$(mktemp -d); chmod 700 "$runtime"; export XDG_RUNTIME_DIR=$runtime
export XDG_CACHE_HOME=$runtime/cache
shoot() { # scene strategy exposure [name, for a scene given as a file]
  local out="screenshots/viewer-${4:-$1}-$2.png"
  wanted "$out" || return 0
  xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
    '$bin' view '$1' --strategy '$2' --exposure '$3' --target-spp 1024 & pid=\$!
    sleep $wait_s
    import -window root '$out'
    kill \$pid; wait \$pid 2>/dev/null || true"
  echo "$out"
}
shoot default emitter 0
shoot cornell-box emitter 1
shoot cornell-box cosine 1
shoot veach-mis brdf 0
shoot veach-mis emitter 0
shoot veach-mis mis 0
shoot near-light emitter -2
shoot occluded-light guided 1
shoot assets/knot-box/knot-box.toml emitter 0 knot-box
shoot_compare() { # name warm-up-seconds seconds scene args…
  # The first run renders the reference into the cache, so the second records convergence from 1 spp.
  local out="screenshots/viewer-compare-$1.png" warm=$2 wait=$3 scene=$4; shift 4
  wanted "$out" || return 0
  xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
    '$bin' view '$scene' $* & pid=\$!
    sleep $warm; kill \$pid; wait \$pid 2>/dev/null || true
    '$bin' view '$scene' $* & pid=\$!
    sleep $wait
    import -window root '$out'
    kill \$pid; wait \$pid 2>/dev/null || true"
  echo "$out"
}
shoot_compare split 45 25 veach-mis --strategy emitter --compare brdf --target-spp 256 --reference-spp 256 --plot
shoot_compare errors 1 15 cornell-box --strategy emitter --compare cosine --view std-error --target-spp 64 --exposure 1
# Fixed primary hits: the standard error is the estimators' own, and solid-angle sampling's is lower under the
# light than emitter sampling's (1/r²).
shoot_compare fixed-hits 50 20 near-light --strategy emitter --compare solid-angle --footprint centre --view std-error --target-spp 256 --reference-spp 256 --plot --exposure -2
# Light through a hole: MIS against guided at equal time, guided training as it refines.
shoot_compare occluded-light 1 40 occluded-light --strategy mis --compare guided --budget equal-time --view std-error --footprint centre --target-spp 1024 --exposure 1
shoot_compare plot 50 30 near-light --strategy emitter --compare projected-solid-angle --budget equal-time --target-spp 512 --reference-spp 512 --plot --exposure -2
shoot_probe() { # name seconds scene args…
  local out="screenshots/viewer-probe-$1.png" wait=$2 scene=$3; shift 3
  wanted "$out" || return 0
  xvfb-run -a -s "-screen 0 1280x800x24" bash -c "
    '$bin' view '$scene' $* & pid=\$!
    sleep $wait
    import -window root '$out'
    kill \$pid; wait \$pid 2>/dev/null || true"
  echo "$out"
}
shoot_probe cornell-box-mis 10 cornell-box --strategy mis --exposure 1 --probe 60,225
shoot_probe veach-mis-mis 10 veach-mis --strategy mis --probe 90,200
shoot_probe veach-mis-emitter 10 veach-mis --strategy emitter --probe 90,200
shoot_probe compare-default 12 default --strategy mis --compare brdf --probe 150,260
# The guide learned under the hole: its density (fourth disk) on the opening the integrand shows.
shoot_probe occluded-light-guided 25 occluded-light --strategy guided --exposure 1 --probe 128,170
# The near light over a glossy floor (α = 30), the lobe inside the light: brdf-polygon's density follows the lobe,
# projected-solid-angle's only the cosine.
glossy=$runtime/glossy-near-light.toml
sed -e "s#obj = \"near-light.obj\"#obj = \"$PWD/assets/near-light/near-light.obj\"#" assets/near-light/near-light.toml >"$glossy"
printf '[mesh.materials.floor]\nkd = [0.2, 0.2, 0.2]\nks = [0.6, 0.6, 0.6]\nalpha = 30.0\n' >>"$glossy"
shoot_probe glossy-near-light-brdf-polygon 12 "$glossy" --strategy brdf-polygon --exposure -3 --probe 128,131
shoot_probe glossy-near-light-projected-solid-angle 12 "$glossy" --strategy projected-solid-angle --exposure -3 --probe 128,131
