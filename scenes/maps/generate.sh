#!/usr/bin/env bash
# Regenerate the deformation maps shipped with `scenes/sphere_deformed.toml`: the F map and the
# cuts file (paper 000 Sec. 4 and 5; DESIGN.md sections 5 and 6) of the lat-long icosphere
# `scenes/meshes/smiley.obj`, the texture running along the parallels around its z axis.
# Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
out=$(mktemp -d)
./target/release/tessera deform scenes/meshes/smiley.obj --orientation parallels:0,0,1 --tile-size 0.1 \
  --smoothing 1 --res 256 -o "$out"
mkdir -p scenes/maps/smiley
cp "$out/f_map.exr" "$out/cuts.json" scenes/maps/smiley/
rm -r "$out"
