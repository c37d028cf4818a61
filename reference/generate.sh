#!/usr/bin/env bash
# Regenerate the Mitsuba 3 references of the golden scenes, from scratch:
# a virtual environment with Mitsuba 3.9.1, tessera's export of each scenes/golden/NAME.toml to
# Mitsuba XML, and a render of the mean image and per-pixel variance into reference/.
#
#   bash reference/generate.sh [NAME ...]      (default: every scene in scenes/golden)
#
# Environment: VENV (default ~/.venv-tessera-mitsuba), SPP (default 16384),
# VARIANT (default llvm_ad_rgb when Debian's libllvm19 is installed or installable, else
# scalar_rgb, about 2.5 times slower). Takes about a minute per scene with llvm_ad_rgb on 2 cores.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
venv=${VENV:-$HOME/.venv-tessera-mitsuba}
spp=${SPP:-16384}

if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q "mitsuba==3.9.1" numpy "openexr>=3.3"

variant=${VARIANT:-}
if [ -z "$variant" ]; then
  # Mitsuba's LLVM variants need LLVM 19 here (Debian's LLVM 15 crashes on these scenes).
  if ! ls /usr/lib/x86_64-linux-gnu/libLLVM.so.19* >/dev/null 2>&1 && command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt-get update -qq && apt-get install -y -qq libllvm19 >/dev/null || true
  fi
  if ls /usr/lib/x86_64-linux-gnu/libLLVM.so.19* >/dev/null 2>&1; then variant=llvm_ad_rgb; else variant=scalar_rgb; fi
fi

"$venv/bin/python" reference/make_textures.py scenes/golden/textures
cargo build --release --quiet

names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in scenes/golden/*.toml; do names+=("$(basename "$f" .toml)"); done
fi
for name in "${names[@]}"; do
  export_dir="target/mitsuba/$name"
  rm -rf "$export_dir"
  target/release/tessera export-mitsuba "scenes/golden/$name.toml" -o "$export_dir" --spp "$spp"
  "$venv/bin/python" reference/render_reference.py "$export_dir/scene.xml" \
    --variant "$variant" --spp "$spp" --seed 1 --source "scenes/golden/$name.toml" \
    --out "reference/$name.exr" --var "reference/$name.var.exr" --meta "reference/$name.meta.toml"
done
