#!/usr/bin/env python3
"""Time Mitsuba 3 on an XML scene: median samples per second over a few renders.

    time_mitsuba.py SCENE.xml --variant llvm_ad_rgb [--runs 3] [--warmup 0] [--threads N]

The first render of an LLVM variant includes compiling its kernels (or loading them from Dr.Jit's
cache); with --warmup 1 it is rendered untimed first, else the median hides it when --runs is at
least 3. --threads sets the worker threads (Dr.Jit's pool, which Mitsuba's scalar variants use too).
"""
import argparse
import os
import statistics
import time

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("scene")
parser.add_argument("--variant", default="llvm_ad_rgb")
parser.add_argument("--runs", type=int, default=3)
parser.add_argument("--warmup", type=int, default=0)
parser.add_argument("--threads", type=int, default=0, help="0: all cores")
args = parser.parse_args()
llvm19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm19):
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm19
import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

mi.set_variant(args.variant)
if args.threads > 0:
    dr.set_thread_count(args.threads)
scene = mi.load_file(args.scene)
film = scene.sensors()[0].film()
spp = scene.sensors()[0].sampler().sample_count()
samples = film.size()[0] * film.size()[1] * spp
for run in range(args.warmup):
    dr.eval(mi.render(scene, seed=1000 + run))
    dr.sync_thread()
rates = []
for run in range(args.runs):
    start = time.perf_counter()
    image = mi.render(scene, seed=run)
    dr.eval(image)
    dr.sync_thread()
    rates.append(samples / (time.perf_counter() - start) / 1e6)
print(f"{args.variant} {statistics.median(rates):.3f} M samples/s (runs: {', '.join(f'{r:.2f}' for r in rates)})")
