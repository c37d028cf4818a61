#!/usr/bin/env python3
"""tessera against Mitsuba 3 in one session: samples per second, alternating, medians, ratios.

    python3 reference/bench.py [--rounds 3] [--threads 2] [--scenes A,D] [--depths 1,2,3]

Scenes: A is scenes/brushed_metal.toml (the render benchmark of `tessera bench`); D is
scenes/bench_deformed.toml (deformed tiling and blending with Mix-Max, an F map and cut bands,
evaluated procedurally by tessera; Mitsuba renders `tessera export-mitsuba`'s bake of it).

Each round renders each scene once with tessera, once with Mitsuba's llvm_ad_rgb and once with
its scalar_rgb, one after the other, so that a machine that slows down or speeds up during the
session affects all three alike; the medians over the rounds are printed with their ratios,
and each round's ratios, which a machine whose speed drifts over the session affects least.
With --depths, each round also renders each scene with those path lengths (max_depth: 1 is the
camera rays and the emitters they see, 2 adds the first vertex's light sample and bounce), and
the medians are printed as nanoseconds a sample and what each longer path adds: where along the
path the time goes, for tessera and for Mitsuba's llvm_ad_rgb.
Rendering time only, for both: tessera's own figure (`tessera render` prints the samples per
second of its rendering, after loading), and Mitsuba's `mi.render` timed around (after loading,
and after one warm-up render that compiles the LLVM kernels). Mitsuba comes from the virtual
environment of reference/generate.sh (VENV, default ~/.venv-tessera-mitsuba); without it only
tessera is measured. Builds tessera in release mode first. Prints the machine first (CPU model and
widest vector instructions): Mitsuba's LLVM variant compiles 16 lanes where the CPU has AVX-512VL
and 8 where it has AVX2, so a ratio holds for the machine it was measured on.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = {"A": "scenes/brushed_metal.toml", "D": "scenes/bench_deformed.toml"}
VARIANTS = ("llvm_ad_rgb", "scalar_rgb")


def tessera_rate(tessera, scene, threads, out, depth=None):
    """tessera's samples per second (millions) rendering `scene` (paths of at most `depth`
    segments where given), as it reports them."""
    depth_args = [] if depth is None else ["--set", f"render.max_depth={depth}"]
    run = subprocess.run(
        [tessera, "render", scene, "--threads", str(threads), "-o", out, *depth_args],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )
    found = re.search(r"\(([0-9.]+) M samples/s\)", run.stdout + run.stderr)
    if not found:
        sys.exit(f"bench.py: no samples/s in tessera's output for {scene}:\n{run.stdout}{run.stderr}")
    return float(found.group(1))


def mitsuba_rate(python, xml, variant, threads):
    """Mitsuba's samples per second (millions) rendering `xml` with `variant` (one warm-up)."""
    run = subprocess.run(
        [python, str(ROOT / "reference/time_mitsuba.py"), xml, "--variant", variant, "--runs", "1",
         "--warmup", "1", "--threads", str(threads)],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )
    return float(run.stdout.split()[1])


def depth_xml(xml, depth):
    """A copy of the exported scene `xml` whose integrator's max_depth is `depth`."""
    text = xml.read_text()
    pattern = r'(<integer name="max_depth" value=")[0-9]+(")'
    if not re.search(pattern, text):
        sys.exit(f"bench.py: no max_depth in {xml}")
    copy = xml.with_name(f"scene_depth{depth}.xml")
    copy.write_text(re.sub(pattern, rf"\g<1>{depth}\g<2>", text))
    return copy


def machine():
    """The CPU's model and its widest vector instructions, which decide how many lanes Mitsuba's
    LLVM variant compiles for (Dr.Jit's LLVM backend: 16 with AVX-512VL, 8 with AVX, 4 with
    SSE4.2): ratios hold for one machine only."""
    model, flags = "unknown CPU", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name" and model == "unknown CPU":
                    model = value.strip()
                elif key.strip() == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    widest = next((isa for isa in ("avx512vl", "avx2", "avx", "sse4_2") if isa in flags), "unknown")
    return f"{model}, {os.cpu_count()} logical CPUs, widest vectors {widest}"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds (the median is printed)")
    parser.add_argument("--threads", type=int, default=2, help="threads of every renderer")
    parser.add_argument("--scenes", default="A,D", help="which scenes, comma separated: A, D")
    parser.add_argument("--depths", default="", help="path lengths (max_depth) to time as well, comma separated")
    args = parser.parse_args()
    if args.rounds < 1:
        sys.exit("bench.py: --rounds must be at least 1")
    try:
        depths = [int(d) for d in args.depths.split(",") if d.strip()]
    except ValueError:
        sys.exit(f"bench.py: --depths takes whole numbers, comma separated, not {args.depths!r}")
    if any(d < 1 or d > 1000 for d in depths):
        sys.exit("bench.py: each of --depths must be 1 to 1000")
    names = args.scenes.split(",")
    for name in names:
        if name not in SCENES:
            sys.exit(f"bench.py: unknown scene {name!r} (A or D)")

    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    tessera = str(ROOT / "target/release/tessera")
    venv = Path(os.environ.get("VENV", Path.home() / ".venv-tessera-mitsuba"))
    python = venv / "bin/python"
    have_mitsuba = python.exists()
    if not have_mitsuba:
        print(f"bench.py: no Mitsuba virtual environment at {venv} (reference/generate.sh makes one); tessera only")
    out = ROOT / "target/bench"
    out.mkdir(parents=True, exist_ok=True)
    print(f"machine: {machine()}", flush=True)

    for name in names:
        scene = SCENES[name]
        xml = out / name / "scene.xml"
        if have_mitsuba:
            subprocess.run([tessera, "export-mitsuba", scene, "-o", str(out / name)], cwd=ROOT, check=True,
                           capture_output=True)
        rates = {"tessera": []} | ({v: [] for v in VARIANTS} if have_mitsuba else {})
        by_depth = {k: {d: [] for d in depths} for k in ["tessera"] + (["llvm_ad_rgb"] if have_mitsuba else [])}
        for round_ in range(args.rounds):
            rates["tessera"].append(tessera_rate(tessera, scene, args.threads, str(out / f"{name}.exr")))
            if have_mitsuba:
                for variant in VARIANTS:
                    rates[variant].append(mitsuba_rate(str(python), str(xml), variant, args.threads))
            print(f"scene {name} round {round_ + 1}: " + ", ".join(f"{k} {v[-1]:.3f}" for k, v in rates.items()),
                  flush=True)
            for depth in depths:
                by_depth["tessera"][depth].append(
                    tessera_rate(tessera, scene, args.threads, str(out / f"{name}.exr"), depth))
                if have_mitsuba:
                    by_depth["llvm_ad_rgb"][depth].append(
                        mitsuba_rate(str(python), str(depth_xml(xml, depth)), "llvm_ad_rgb", args.threads))
        median = {k: statistics.median(v) for k, v in rates.items()}
        print(f"scene {name} ({scene}), {args.threads} threads, medians of {args.rounds} rounds:")
        for k, v in median.items():
            ratio = "" if k == "tessera" else f"   tessera / {k} = {median['tessera'] / v:.2f}x"
            print(f"  {k:<12} {v:7.3f} M samples/s{ratio}")
        # Each round's renders run seconds apart, so a round's ratio cancels the machine's drift
        # over the session, which the ratio of medians (above, the headline) does not.
        for k, v in rates.items():
            if k != "tessera":
                paired = sorted(t / m for t, m in zip(rates["tessera"], v))
                print(f"  tessera / {k} round by round: " + ", ".join(f"{r:.2f}x" for r in paired)
                      + f" (median {statistics.median(paired):.2f}x)")
        if depths:
            print(f"scene {name} by path length: ns a sample ({args.threads} threads; + what the longer paths add)")
            for renderer, rates_of in by_depth.items():
                ns = {d: 1e3 / statistics.median(r) for d, r in rates_of.items()}
                ns["full"] = 1e3 / median[renderer]
                previous, cells = 0.0, []
                for d, t in ns.items():
                    cells.append(f"{d}: {t:6.1f} (+{t - previous:5.1f})")
                    previous = t
                print(f"  {renderer:<12} " + "  ".join(cells))


if __name__ == "__main__":
    main()
