#!/bin/sh
# Path guiding against MIS (issue 21's measurement): `guided` (trained within its samples, 64 training spp by
# default, training included in the time and in the image) against `mis` and `emitter` at 64, 256 and 1024 spp,
# 8 seeds, fixed primary hits, on occluded-light (where the guide should win) and the Cornell box (where there is
# nothing to learn). References at 16 384 spp: guided's on occluded-light (MIS resolves the hole slowly), MIS's
# on the Cornell box. Writes docs/bench/guided/<scene>/. Run it on an otherwise idle machine: timings are
# wall-clock. Extra arguments go to every bench (e.g. --train-spp 256).
set -e
cd "$(dirname "$0")/.."
cargo build --release
bin=target/release/illumlab
$bin bench occluded-light --strategies emitter,mis,guided --spp 64,256,1024 --reference-spp 16384 \
    --reference-strategy guided --out docs/bench/guided/occluded-light "$@"
$bin bench cornell-box --strategies emitter,mis,guided --spp 64,256,1024 --reference-spp 16384 \
    --out docs/bench/guided/cornell-box "$@"
rm -f docs/bench/guided/*/reference.exr docs/bench/guided/*/reference.var.exr
