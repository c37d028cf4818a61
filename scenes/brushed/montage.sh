#!/usr/bin/env bash
# Render the four Fig. 8 scenes of this folder and lay them out as paper 000's Fig. 8:
# parameterisations in rows, classical and deformed tiling and blending in columns, written to
# the folder given (default: target/fig8). Also prints each render's seam visibility (`tessera
# seams`) and relMSE between the two parameterisations' renders, classical and deformed
# (deformed should be nearly independent of the parameterisation). Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-target/fig8}
spp=${SPP:-64}
mkdir -p "$out"
cargo build --release --locked
for scene in latlong_classical latlong_deformed cube_classical cube_deformed; do
  ./target/release/tessera render "scenes/brushed/$scene.toml" --spp "$spp" -q --aov uv,normal -o "$out/$scene.exr"
  echo "$scene: $(./target/release/tessera seams "$out/$scene.exr")"
done
./target/release/tessera montage --columns 2 \
  "$out/latlong_classical.exr" --label "lat-long, classical" \
  "$out/latlong_deformed.exr" --label "lat-long, deformed" \
  "$out/cube_classical.exr" --label "cube map, classical" \
  "$out/cube_deformed.exr" --label "cube map, deformed" \
  -o "$out/fig8.png"
for kind in classical deformed; do
  echo "$kind: lat-long against cube map"
  ./target/release/tessera diff "$out/latlong_$kind.exr" "$out/cube_$kind.exr" --max-relmse 1e6
done
