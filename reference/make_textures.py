#!/usr/bin/env python3
"""Write the textures of the golden scenes (scenes/golden/textures/), deterministically.

  asym.png       64x64 8-bit sRGB: quadrants red (top-left), green, blue, yellow and a white
                 "F" in the top-left quadrant; no symmetry, so any flip or rotation of the UV
                 convention shows.
  bumps.png      64x64 8-bit tangent-space normal map (RGB = (n + 1) / 2) of a grid of smooth
                 bumps, tilted more along u than v, so a swapped tangent frame shows.
  uvtex.exr      1024x512 float RGB: the "baked procedural" texture of Mitsuba test scene B
                 (gen_assets.py of the Mitsuba tools: colour ramps, a fine checker, thin dark
                 lines and a red square at uv (0, 1)), at half its resolution.

Needs numpy and OpenEXR (the reference virtual environment has both). PNGs are written with zlib.
"""
import os
import struct
import sys
import zlib

import numpy as np


def write_png(path, img):
    h, w, _ = img.shape
    raw = b"".join(b"\x00" + img[y].tobytes() for y in range(h))

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def asym(path):
    n = 64
    img = np.zeros((n, n, 3), np.uint8)
    img[: n // 2, : n // 2] = (200, 30, 30)
    img[: n // 2, n // 2 :] = (30, 170, 40)
    img[n // 2 :, : n // 2] = (40, 60, 200)
    img[n // 2 :, n // 2 :] = (220, 200, 40)
    # An "F": stem on the left, bars at the top and middle.
    img[6:28, 8:12] = 255
    img[6:10, 8:24] = 255
    img[15:19, 8:20] = 255
    write_png(path, img)


def bumps(path):
    n = 64
    y, x = np.mgrid[0:n, 0:n].astype(np.float64)
    u = (x + 0.5) / n
    v = 1.0 - (y + 0.5) / n
    # Height h = a_u sin(2 pi 4 u) + a_v sin(2 pi 4 v); slopes give the normal.
    dhdu = 0.35 * np.cos(8 * np.pi * u)
    dhdv = 0.12 * np.cos(8 * np.pi * v)
    nrm = np.stack([-dhdu, -dhdv, np.ones_like(u)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    write_png(path, np.round((nrm + 1.0) * 0.5 * 255.0).astype(np.uint8))


def uvtex(path, w=1024, h=512):
    import OpenEXR

    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    u = (x + 0.5) / w
    v = 1.0 - (y + 0.5) / h
    fine = ((np.floor(u * 128) + np.floor(v * 64)) % 2).astype(np.float32)
    rgb = np.stack([(0.15 + 0.7 * u) * (0.6 + 0.4 * fine), (0.15 + 0.7 * v) * (0.6 + 0.4 * fine), 0.2 + 0.6 * fine], -1)
    lines = ((x % (w // 16)) < 1) | ((y % (h // 8)) < 1)
    rgb[lines] = 0.02
    rgb[: h // 16, : h // 16] = (0.8, 0.05, 0.05)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb.astype(np.float32))}).write(path)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "golden", "textures")
    os.makedirs(out, exist_ok=True)
    asym(os.path.join(out, "asym.png"))
    bumps(os.path.join(out, "bumps.png"))
    uvtex(os.path.join(out, "uvtex.exr"))


if __name__ == "__main__":
    main()
