#!/usr/bin/env bash
# Regenerate the golden bakes of PUPs presets (paper 002) that `tests/pups.rs` compares: 128 x
# 128 EXR, fixed seeds, one value preset and one label preset, plain and tileable. Run from
# anywhere. The presets use libm's trigonometry and powers, so the bakes are the same on every
# platform.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
./target/release/tessera pups turbulence --points 400 --seed 3 --res 128 128 -o reference/pups/turbulence_seed3.exr
./target/release/tessera pups cow --points 300 --seed 5 --tileable --res 128 128 -o reference/pups/cow_seed5_tileable.exr
