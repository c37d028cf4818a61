#!/usr/bin/env bash
# Regenerate the maps of `blub.toml` (paper 000 Fig. 9): the F map and cuts of Keenan Crane's
# Blub (`scenes/meshes/blub.obj`, five UV charts) with the texture running away from its mouth
# along the geodesic distance over the surface. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
out=$(mktemp -d)
./target/release/tessera deform scenes/meshes/blub.obj --orientation "geodesic:0,0,1" --tile-size 0.02 --res 512 -o "$out"
mkdir -p scenes/fig9/maps
cp "$out/f_map.exr" "$out/cuts.json" scenes/fig9/maps/
rm -r "$out"
