#!/usr/bin/env python3
"""Deinterlacing quality with a known truth, for bench/deinterlace.sh.

  deint_psnr.py make PHOTO W H N DIR     write DIR/in/%04d.png (N interlaced frames,
                                         bottom field first) and DIR/truth/%04d.png
  deint_psnr.py score DIR PATTERN        pooled PSNR (dB, 8-bit RGB) of the frames
                                         PATTERN % k (k = 1..N) against DIR/truth

The progressive source is a camera move over PHOTO at field rate: a pan of 3 px
right and 1 px down per field with a slow zoom (bilinear resampling of a region
scaled to W x H). Interlaced frame k (1-based) has the bottom field (odd rows)
of progressive picture 2k - 2 and the top field (even rows) of picture 2k - 1; a
deinterlacer that keeps the first field should reproduce picture 2k - 2, which is
the truth. The first and last frames are included.
"""
import os
import sys

import cv2
import numpy as np


def make(photo, w, h, n, out):
    src = cv2.imread(photo, cv2.IMREAD_COLOR)
    if src is None:
        sys.exit(f"cannot read {photo}")
    sh, sw = src.shape[:2]
    # Region 1.6x the output size (at most the photo), moving and zooming slowly.
    rw = min(sw * 0.6, w * 1.6)
    scale0 = rw / w
    os.makedirs(f"{out}/in", exist_ok=True)
    os.makedirs(f"{out}/truth", exist_ok=True)

    def picture(t):
        s = scale0 * (1.0 - 0.002 * t)
        x0 = sw * 0.2 + 3.0 * t * s
        y0 = sh * 0.2 + 1.0 * t * s
        m = np.array([[1.0 / s, 0.0, -x0 / s], [0.0, 1.0 / s, -y0 / s]])
        return cv2.warpAffine(src, m, (w, h), flags=cv2.INTER_AREA if s > 1 else cv2.INTER_LINEAR,
                              borderMode=cv2.BORDER_REFLECT)

    for k in range(1, n + 1):
        first = picture(2 * k - 2)
        second = picture(2 * k - 1)
        woven = first.copy()
        woven[0::2] = second[0::2]  # top field from the later picture (bff)
        cv2.imwrite(f"{out}/in/{k:04d}.png", woven, [cv2.IMWRITE_PNG_COMPRESSION, 1])
        cv2.imwrite(f"{out}/truth/{k:04d}.png", first, [cv2.IMWRITE_PNG_COMPRESSION, 1])


def score(d, pattern):
    se, count, k = 0.0, 0, 1
    while os.path.exists(f"{d}/truth/{k:04d}.png"):
        t = cv2.imread(f"{d}/truth/{k:04d}.png", cv2.IMREAD_COLOR).astype(np.float64)
        o = cv2.imread(pattern % k, cv2.IMREAD_COLOR)
        if o is None:
            sys.exit(f"missing {pattern % k}")
        se += float(((o.astype(np.float64) - t) ** 2).sum())
        count += t.size
        k += 1
    mse = se / count
    print(f"{10 * np.log10(255.0 ** 2 / mse):.2f}")


if __name__ == "__main__":
    if sys.argv[1] == "make":
        make(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6])
    elif sys.argv[1] == "score":
        score(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
