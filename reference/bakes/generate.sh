#!/usr/bin/env bash
# Regenerate the texture-space golden bakes of the Fig. 2 scenes (paper 000): 128 x 128, one
# texel footprints, as `tests/golden_bakes.rs` compares them. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
for kind in rotation scaling shearing; do
  ./target/release/tessera bake "scenes/fig2_$kind.toml" --texture synthesis --res 128 -o "reference/bakes/fig2_$kind.exr"
done
