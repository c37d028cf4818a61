#!/usr/bin/env bash
# Figures that compare tessera with Mitsuba 3, for reports:
#  1. per golden scene, at equal samples per pixel (SPP, default 122: the golden tests' budget),
#     relMSE of tessera against Mitsuba (seed A) beside relMSE of Mitsuba seed A against seed B:
#     two renderers that agree differ by their noise alone, as two seeds do; and the fraction of
#     pixels that pass the golden Z-test against the reference, for Mitsuba (seed A) and for
#     tessera: a scene is fit for the test when Mitsuba passes it against its own reference;
#  2. samples per second on scenes/brushed_metal.toml (512x512, 64 spp, max depth 8, 2 threads):
#     tessera, Mitsuba scalar_rgb and Mitsuba llvm_ad_rgb, measured one after the other in this run.
# Needs the virtual environment of reference/generate.sh (VENV).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
venv=${VENV:-$HOME/.venv-tessera-mitsuba}
spp=${SPP:-122}
variant=${VARIANT:-llvm_ad_rgb}
out=target/report
mkdir -p "$out"
cargo build --release --quiet
relmse() { target/release/tessera diff "$1" "$2" --max-relmse 1e9 | awk '/^relmse/ {print $2}'; }
ztest() { target/release/tessera diff "$1" "reference/$2.exr" --variance "reference/$2.var.exr" --spp "$spp" | awk '/^z-test/ {print $2}'; }

printf '%-18s %14s %14s %8s %10s %10s\n' scene "tessera-vs-mi" "mi-A-vs-mi-B" ratio "z mi-A" "z tessera"
for f in scenes/golden/*.toml; do
  name=$(basename "$f" .toml)
  target/release/tessera export-mitsuba "$f" -o "$out/$name" --spp "$spp" 2>/dev/null
  for seed in 11 12; do
    "$venv/bin/python" reference/render_reference.py "$out/$name/scene.xml" --variant "$variant" \
      --spp "$spp" --seed "$seed" --out "$out/$name.mitsuba$seed.exr" >/dev/null
  done
  target/release/tessera render "$f" --spp "$spp" --seed 3 -q -o "$out/$name.tessera.exr"
  a=$(relmse "$out/$name.tessera.exr" "$out/$name.mitsuba11.exr")
  b=$(relmse "$out/$name.mitsuba12.exr" "$out/$name.mitsuba11.exr")
  printf '%-18s %14s %14s %8.3f %10s %10s\n' "$name" "$a" "$b" "$(python3 -c "print($a / $b)")" \
    "$(ztest "$out/$name.mitsuba11.exr" "$name")" "$(ztest "$out/$name.tessera.exr" "$name")"
done

echo
echo "scenes/brushed_metal.toml, 512x512, 64 spp, max depth 8, 2 threads:"
target/release/tessera export-mitsuba scenes/brushed_metal.toml -o "$out/bench" 2>/dev/null
t=$(for run in 1 2 3; do target/release/tessera render scenes/brushed_metal.toml --threads 2 -o "$out/bench.exr" 2>&1 \
  | grep -o '[0-9.]* M samples/s' | cut -d' ' -f1; done | sort -n | sed -n 2p)
s=$("$venv/bin/python" reference/time_mitsuba.py "$out/bench/scene.xml" --variant scalar_rgb | cut -d' ' -f2)
l=$("$venv/bin/python" reference/time_mitsuba.py "$out/bench/scene.xml" --variant llvm_ad_rgb | cut -d' ' -f2)
echo "tessera      $t M samples/s (median of 3)"
echo "scalar_rgb   $s M samples/s -> tessera / scalar_rgb = $(python3 -c "print(round($t / $s, 2))")"
echo "llvm_ad_rgb  $l M samples/s -> tessera / llvm_ad_rgb = $(python3 -c "print(round($t / $l, 2))")"
