#!/usr/bin/env python3
"""Render a Mitsuba 3 reference: the mean image and the per-pixel variance of one sample.

    render_reference.py SCENE.xml --spp 16384 --out NAME.exr --var NAME.var.exr --meta NAME.meta.toml

The scene's own integrator is wrapped by a small integrator that returns its radiance L and, as
three extra channels, L^2 per RGB channel. With a box reconstruction filter each sample lands in
its own pixel with weight 1, so over N samples of a pixel
    mean = sum(L) / N,   var = (sum(L^2) / N - mean^2) * N / (N - 1),
which is what the Z-test of tessera's golden tests needs. (Mitsuba's `moment` integrator records
moments of CIE XYZ, not of RGB.) The samples are split into passes of --pass-spp, accumulated in
float64; pass k uses seed (seed * 1000 + k).
"""
import argparse
import datetime
import os
import sys
import time

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("scene")
parser.add_argument("--variant", default="llvm_ad_rgb")
parser.add_argument("--spp", type=int, default=16384)
parser.add_argument("--pass-spp", type=int, default=1024)
parser.add_argument("--seed", type=int, default=1)
parser.add_argument("--out", required=True, help="mean image (float32 RGB EXR)")
parser.add_argument("--var", help="per-sample variance (float32 RGB EXR)")
parser.add_argument("--meta", help="how the reference was made (TOML)")
parser.add_argument("--source", default="", help="the tessera scene the XML was exported from, for the metadata")
args = parser.parse_args()

# Dr.Jit loads the last libLLVM it finds; Debian's LLVM 15 cannot compile Mitsuba's kernels.
llvm19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm19):
    os.environ["DRJIT_LIBLLVM_PATH"] = llvm19

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402
import numpy as np  # noqa: E402
import OpenEXR  # noqa: E402

mi.set_variant(args.variant)


class RgbMoments(mi.SamplingIntegrator):
    """The nested integrator's radiance, plus its square per channel as three AOVs."""

    def __init__(self, props):
        super().__init__(props)
        self.nested = props["nested"]

    def sample(self, scene, sampler, ray, medium, active):
        L, valid, _ = self.nested.sample(scene, sampler, ray, medium, active)
        return L, valid, [L.x * L.x, L.y * L.y, L.z * L.z]

    def aov_names(self):
        return ["m2.R", "m2.G", "m2.B"]

    def to_string(self):
        return "RgbMoments[]"


mi.register_integrator("tessera_rgb_moments", lambda props: RgbMoments(props))

if args.spp % args.pass_spp != 0 and args.spp > args.pass_spp:
    sys.exit(f"--spp {args.spp} must be a multiple of --pass-spp {args.pass_spp}")
pass_spp = min(args.spp, args.pass_spp)
passes = args.spp // pass_spp

scene = mi.load_file(args.scene)
integrator = mi.load_dict({"type": "tessera_rgb_moments", "nested": scene.integrator()})
start = time.perf_counter()
total = None
for k in range(passes):
    image = np.asarray(mi.render(scene, integrator=integrator, spp=pass_spp, seed=args.seed * 1000 + k), dtype=np.float64)
    dr.sync_thread()
    total = image if total is None else total + image
seconds = time.perf_counter() - start
# Channels: R, G, B, then the AOVs (Mitsuba may insert an alpha channel after RGB).
channels = total.shape[-1]
mean = total[..., 0:3] / passes
m2 = total[..., channels - 3 : channels] / passes
var = np.maximum(m2 - mean * mean, 0.0) * args.spp / max(args.spp - 1, 1)


def write_exr(path, rgb):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb.astype(np.float32))}).write(path)


write_exr(args.out, mean)
if args.var:
    write_exr(args.var, var)
h, w = mean.shape[:2]
print(f"{args.out}: {w}x{h}, {args.spp} spp, {seconds:.1f} s, {w * h * args.spp / seconds / 1e6:.2f} M samples/s ({args.variant})")
if args.meta:
    command = " ".join([os.path.basename(sys.argv[0])] + sys.argv[1:])
    with open(args.meta, "w") as f:
        f.write(f'# How reference/{os.path.basename(args.out)} was made; regenerate with reference/generate.sh.\n')
        f.write(f'generator = "mitsuba {mi.__version__} (drjit {dr.__version__})"\n')
        f.write(f'variant = "{args.variant}"\n')
        f.write(f'source = "{args.source}"\n')
        f.write(f"spp = {args.spp}\n")
        f.write(f"pass_spp = {pass_spp}\n")
        f.write(f"seed = {args.seed}\n")
        f.write(f"width = {w}\n")
        f.write(f"height = {h}\n")
        f.write(f"seconds = {seconds:.1f}\n")
        f.write(f'date = "{datetime.date.today().isoformat()}"\n')
        f.write(f'command = "{command}"\n')
