#!/usr/bin/env bash
# Regenerate the F maps of paper 000's Fig. 4 sequence (`fig4.toml`) from the lat-long
# icosphere `scenes/meshes/smiley.obj`: S only (F = S, the texture along the UV iso-lines),
# R(theta) S per triangle (the texture along the circles around an axis tilted 45 degrees from
# the poles, not smoothed), and R(theta) S
# smoothed per chart. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
for spec in "stretch uv 1" "triangles parallels:1,0,1 triangles" "smoothed parallels:1,0,1 1"; do
  set -- $spec
  out=$(mktemp -d)
  ./target/release/tessera deform scenes/meshes/smiley.obj --orientation "$2" --smoothing "$3" --tile-size 0.05 \
    --res 256 -o "$out"
  mkdir -p "scenes/fig4/maps/$1"
  cp "$out/f_map.exr" "scenes/fig4/maps/$1/"
  rm -r "$out"
done
