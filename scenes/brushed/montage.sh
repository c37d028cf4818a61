#!/usr/bin/env bash
# Render the Fig. 8 scenes of this folder and lay them out as paper 000's Fig. 8: each mesh under
# two parameterisations in rows (the unit sphere: lat-long and cube map; Spot: its own atlas and
# a box unwrap), classical and deformed tiling and blending in columns, written to the folder
# given (default: target/fig8). Also prints each render's seam visibility (`tessera seams`) and
# relMSE between each mesh's two parameterisations' renders, classical and deformed (deformed
# should be nearly independent of the parameterisation). Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-target/fig8}
spp=${SPP:-64}
mkdir -p "$out"
cargo build --release --locked
declare -A caption=([latlong]="sphere, lat-long" [cube]="sphere, cube map" [spot_atlas]="Spot, its atlas" [spot_box]="Spot, box unwrap")
images=()
for param in latlong cube spot_atlas spot_box; do
  for kind in classical deformed; do
    scene="${param}_$kind"
    ./target/release/tessera render "scenes/brushed/$scene.toml" --spp "$spp" -q --aov uv,normal -o "$out/$scene.exr"
    echo "$scene: $(./target/release/tessera seams "$out/$scene.exr")"
    images+=("$out/$scene.exr" --label "${caption[$param]}, $kind")
  done
done
./target/release/tessera montage --columns 2 "${images[@]}" -o "$out/fig8.png"
for pair in "latlong cube" "spot_atlas spot_box"; do
  set -- $pair
  for kind in classical deformed; do
    echo "$kind: $1 against $2"
    ./target/release/tessera diff "$out/$1_$kind.exr" "$out/$2_$kind.exr" --max-relmse 1e6
  done
done
