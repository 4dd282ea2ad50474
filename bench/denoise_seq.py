#!/usr/bin/env python3
"""Test sequences for bench/denoise.sh: a slow camera pan over a real photo.

  denoise_seq.py make PHOTO OUTDIR WIDTH HEIGHT FRAMES SIGMA8 [SPEED]
      OUTDIR/clean/%04d.png  the pan: a WIDTHxHEIGHT window moving by
                             (1.3, 0.55) px per frame plus a slow sine wobble
                             (sub-pixel positions throughout; all of it times
                             SPEED, default 1; 0: a still camera), cut from the
                             photo at twice the size (Lanczos shift) and
                             area-downscaled, so every frame is a clean image
      OUTDIR/noisy/%04d.png  clean + Gaussian noise of standard deviation
                             SIGMA8 (8-bit sRGB code values, independent per
                             channel, fixed seed), rounded and clipped
  denoise_seq.py psnr CLEAN_DIR OUT_DIR SKIP [PREFIX]
      mean PSNR (dB, 8-bit RGB, peak 255) over frames SKIP+1.. of the sorted
      PNGs, matched in order
  denoise_seq.py ghost CLEAN_DIR OUT_DIR SKIP [PREFIX]
      99.9th percentile of |out - clean| (8-bit) over the same frames: ghost
      trails and misregistered edges show up here before they move the PSNR
"""
import glob
import os
import sys

import cv2
import numpy as np


def make(photo, outdir, w, h, frames, sigma8, speed=1.0):
    src = cv2.imread(photo, cv2.IMREAD_COLOR)
    if src is None:
        sys.exit(f"cannot read {photo}")
    # Work at twice the output size: the window, 2w x 2h, must fit with the pan.
    travel_x, travel_y = 1.3 * frames + 4, 0.55 * frames + 4
    need_w, need_h = 2 * (w + travel_x + 8), 2 * (h + travel_y + 8)
    scale = max(need_w / src.shape[1], need_h / src.shape[0])
    if scale > 1:
        src = cv2.resize(src, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
    else:
        # Shrink the photo so the pan covers a fair part of it (not just a corner).
        f = max(scale, 0.5)
        src = cv2.resize(src, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
    rng = np.random.default_rng(12345)
    os.makedirs(f"{outdir}/clean", exist_ok=True)
    os.makedirs(f"{outdir}/noisy", exist_ok=True)
    x0, y0 = 8.0, 8.0
    for t in range(frames):
        ox = x0 + speed * (1.3 * t + 0.6 * np.sin(t / 4.0))
        oy = y0 + speed * (0.55 * t + 0.3 * np.cos(t / 3.0))
        # Translate the 2x image by -(2 ox, 2 oy) with Lanczos, take the 2w x 2h
        # window at the origin, area-downscale to w x h.
        m = np.float32([[1, 0, -2 * ox], [0, 1, -2 * oy]])
        win = cv2.warpAffine(src, m, (2 * w, 2 * h), flags=cv2.INTER_LANCZOS4,
                             borderMode=cv2.BORDER_REFLECT)
        clean = cv2.resize(win, (w, h), interpolation=cv2.INTER_AREA)
        noisy = clean.astype(np.float64) + rng.normal(0.0, sigma8, clean.shape)
        noisy = np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
        cv2.imwrite(f"{outdir}/clean/{t + 1:04d}.png", clean, [cv2.IMWRITE_PNG_COMPRESSION, 1])
        cv2.imwrite(f"{outdir}/noisy/{t + 1:04d}.png", noisy, [cv2.IMWRITE_PNG_COMPRESSION, 1])


def pairs(clean_dir, out_dir, skip, prefix):
    c = sorted(glob.glob(f"{clean_dir}/*.png"))
    o = sorted(glob.glob(f"{out_dir}/{prefix}*.png"))
    if len(c) != len(o) or not c:
        sys.exit(f"{out_dir}: {len(o)} frames, {clean_dir}: {len(c)}")
    for a, b in list(zip(c, o))[skip:]:
        yield (cv2.imread(a, cv2.IMREAD_COLOR).astype(np.float64),
               cv2.imread(b, cv2.IMREAD_COLOR).astype(np.float64))


def psnr(clean_dir, out_dir, skip, prefix=""):
    v = [10 * np.log10(255.0 ** 2 / max(np.mean((a - b) ** 2), 1e-12))
         for a, b in pairs(clean_dir, out_dir, skip, prefix)]
    print(f"{np.mean(v):.2f}")


def ghost(clean_dir, out_dir, skip, prefix=""):
    v = [np.percentile(np.abs(a - b).max(axis=2), 99.9)
         for a, b in pairs(clean_dir, out_dir, skip, prefix)]
    print(f"{np.mean(v):.1f}")


if __name__ == "__main__":
    cmd, args = sys.argv[1], sys.argv[2:]
    if cmd == "make":
        make(args[0], args[1], int(args[2]), int(args[3]), int(args[4]), float(args[5]),
             *map(float, args[6:7]))
    elif cmd == "psnr":
        psnr(args[0], args[1], int(args[2]), *args[3:])
    elif cmd == "ghost":
        ghost(args[0], args[1], int(args[2]), *args[3:])
    else:
        sys.exit(__doc__)
