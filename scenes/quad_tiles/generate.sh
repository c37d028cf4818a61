#!/usr/bin/env bash
# Regenerate paper 001's shipped tiles: two tile images synthesised from photographs
# (`tessera tiles synth`), their contact sheets, and two quad meshes mapped to them
# (`tessera tiles map`): Blub's quad mesh (valences 3 to 7) and a cube (valence 3) smoothed by
# four rounds of Catmull-Clark subdivision after mapping, as the paper's Fig. 7 is.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
t=./target/release/tessera
out=scenes/quad_tiles
$t tiles synth scenes/textures/rocks_basecolor.jpg --tile-res 64 --seed 1 \
    --sheet "$out/rocks_sheet.png" -o "$out/rocks_tiles.png"
$t tiles synth scenes/textures/rock2.jpg --tile-res 64 --seed 2 \
    --sheet "$out/rock2_sheet.png" -o "$out/rock2_tiles.png"
$t tiles map scenes/meshes/blub.obj --seed 1 --texture rocks_tiles.png -o "$out/blub_tiled.obj"
$t tiles map scenes/meshes/cube_quads.obj --seed 2 --subdivide 4 --texture rock2_tiles.png -o "$out/cube_tiled.obj"
