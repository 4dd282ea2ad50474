"""Agreement of blurred PNGs with OpenCV's GaussianBlur on the same input.

    python3 bench/blur_accuracy.py INPUT SIGMA NAME=OUTPUT...

The reference is cv2.GaussianBlur(img, (0, 0), SIGMA, borderType=BORDER_REPLICATE) on
the stored 8-bit values (what vips, ffmpeg and `fxrun --assume-linear` compute). For
each output: the largest difference in LSB, the share of samples more than 1 LSB off,
and the PSNR against the reference.
"""
import os
import sys

import cv2
import numpy as np

src = cv2.imread(sys.argv[1], cv2.IMREAD_UNCHANGED)
sigma = float(sys.argv[2])
ref = cv2.GaussianBlur(src, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE).astype(np.float64)
print(f"  {'output':<36} {'max LSB':>8} {'> 1 LSB':>9} {'PSNR':>9}")
for arg in sys.argv[3:]:
    name, path = arg.rsplit("=", 1)
    out = cv2.imread(path, cv2.IMREAD_UNCHANGED) if os.path.exists(path) else None
    if out is None:
        print(f"  {name:<36} (not run)")
        continue
    out = out.astype(np.float64)
    if out.ndim == 3 and out.shape[2] != ref.shape[2]:
        out = out[..., : ref.shape[2]]
    d = np.abs(out - ref)
    mse = (d**2).mean()
    psnr = 10 * np.log10(255**2 / mse) if mse > 0 else float("inf")
    print(f"  {name:<36} {d.max():8.0f} {100 * (d > 1).mean():8.3f}% {psnr:8.2f} dB")
