#!/usr/bin/env bash
# Regenerate the deformation maps of the Fig. 8 scenes in this folder: the F map and cuts of the
# lat-long icosphere (texture along the parallels around its z axis, which the scenes turn
# upright), of the cube-map sphere (parallels around y), and of Spot under its own atlas and
# under the box unwrap of `../meshes/make_spot_parameterisations.py` (parallels around z, the body's
# length). Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
for spec in "latlong scenes/meshes/smiley.obj parallels:0,0,1" "cube scenes/meshes/cube_sphere.obj parallels:0,1,0" \
  "spot_atlas scenes/meshes/spot_atlas.obj parallels:0,0,1" "spot_box scenes/meshes/spot_box_uv.obj parallels:0,0,1"; do
  set -- $spec
  out=$(mktemp -d)
  ./target/release/tessera deform "$2" --orientation "$3" --tile-size 0.04 --res 256 -o "$out"
  mkdir -p "scenes/brushed/maps/$1"
  cp "$out/f_map.exr" "$out/cuts.json" "scenes/brushed/maps/$1/"
  rm -r "$out"
done
