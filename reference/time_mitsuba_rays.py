#!/usr/bin/env python3
"""Time Mitsuba 3's ray queries on scene A's first bounces from its ground: Mrays/s.

    time_mitsuba_rays.py SCENE.xml [--variant llvm_ad_rgb] [--runs 5] [--threads 2] [--rays 2097152]

(--variant: an LLVM variant; the scalar ones take one ray at a time from Python.)

SCENE.xml is `tessera export-mitsuba scenes/brushed_metal.toml`'s (reference/bench.py writes it to
target/bench/A/scene.xml). The rays are drawn as tessera's `bench --only rays` draws them for its
"scene A ground bounces" figure (a different random sequence, the same distribution): origins
uniform over x, z in [-3, 3], 1e-4 above the ground (y = -1), cosine-distributed directions about
+y. Closest hits (`ray_intersect_preliminary`, the distance evaluated) and occlusion (`ray_test`),
medians of --runs after one untimed run that compiles the kernels. Run it with the Python of the
Mitsuba virtual environment (reference/generate.sh), which has numpy.
"""
import argparse
import os
import statistics
import time

import numpy as np

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("scene")
parser.add_argument("--variant", default="llvm_ad_rgb")
parser.add_argument("--runs", type=int, default=5)
parser.add_argument("--threads", type=int, default=2)
parser.add_argument("--rays", type=int, default=1 << 21)
args = parser.parse_args()
if args.runs < 1 or not 1 <= args.rays <= 1 << 26:
    parser.error("--runs must be at least 1 and --rays 1 to 2^26")
if not args.variant.startswith("llvm"):
    parser.error(f"--variant must be an LLVM (vectorised) variant, which takes arrays of rays, not {args.variant}")
llvm19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm19):
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm19
import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

mi.set_variant(args.variant)
dr.set_thread_count(args.threads)
scene = mi.load_file(args.scene)

rng = np.random.default_rng(5)
n = args.rays
x, z = rng.uniform(-3.0, 3.0, n), rng.uniform(-3.0, 3.0, n)
u1, u2 = rng.uniform(size=n), rng.uniform(size=n)
r, phi = np.sqrt(u1), 2.0 * np.pi * u2
origin = mi.Point3f(x.astype(np.float32), np.full(n, -1.0 + 1e-4, np.float32), z.astype(np.float32))
direction = mi.Vector3f((r * np.cos(phi)).astype(np.float32), np.sqrt(np.maximum(0.0, 1.0 - u1)).astype(np.float32),
                        (r * np.sin(phi)).astype(np.float32))
ray = mi.Ray3f(origin, direction)

queries = {"closest": lambda: scene.ray_intersect_preliminary(ray).t, "occluded": lambda: scene.ray_test(ray)}
rates = {}
for name, query in queries.items():
    times = []
    for run in range(args.runs + 1):
        dr.sync_thread()
        start = time.perf_counter()
        dr.eval(query())
        dr.sync_thread()
        if run > 0:
            times.append(time.perf_counter() - start)
    rates[name] = n / statistics.median(times) / 1e6
hit = float(np.isfinite(np.array(scene.ray_intersect_preliminary(ray).t)).mean())
print(f"mitsuba {args.variant} scene A ground bounces {n} rays ({100 * hit:.0f}% hit): "
      f"closest {rates['closest']:.2f} Mrays/s, occluded {rates['occluded']:.2f}, {args.threads} threads")
