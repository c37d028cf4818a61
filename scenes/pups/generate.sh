#!/usr/bin/env bash
# Regenerate the PUPs gallery (paper 002 Sec. 3): every preset baked to a 384 x 384 PNG with a
# fixed seed, tileable, and a labelled contact sheet of all of them (`gallery.png`).
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
t=./target/release/tessera
out=scenes/pups
presets="noise octaves turbulence cells clustered-cells multiscale-cells cow space-giraffe reference-labels iterative progressive-cow progressive-giraffe label-ramp"
files=()
for p in $presets; do
  $t pups "$p" --points 500 --seed 1 --tileable --res 384 384 -o "$out/$p.png"
  files+=("$out/$p.png")
done
$t montage "${files[@]}" --columns 5 -o "$out/gallery.png"
