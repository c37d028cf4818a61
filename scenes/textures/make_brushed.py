"""Make scenes/textures/brushed.png: a tileable brushed-metal exemplar, white noise blurred
along x (sigma 24 texels) and barely across (sigma 0.8), periodic, 256 x 256, 8-bit grey.
Run with numpy and Pillow: python3 make_brushed.py"""
import numpy as np
from PIL import Image

rng = np.random.default_rng(7)
n = 256
noise = rng.standard_normal((n, n))
fx = np.fft.fftfreq(n)[None, :]
fy = np.fft.fftfreq(n)[:, None]
sx, sy = 24.0, 0.8
kernel = np.exp(-2 * np.pi**2 * ((fx * sx) ** 2 + (fy * sy) ** 2))
field = np.real(np.fft.ifft2(np.fft.fft2(noise) * kernel))
field = (field - field.mean()) / field.std()
img = np.clip(0.5 + 0.18 * field, 0, 1)
Image.fromarray((img * 255 + 0.5).astype(np.uint8)).save("brushed.png")
