#!/usr/bin/env python3
"""The glow of effects/glow.fx written with OpenCV, as a peer for bench/compare.sh.

Same maths as the fxgraph shaders: linearise sRGB, soft-knee bright pass
(threshold 0.7, knee 0.2), downsample to half size, separable Gaussian
(sigma 4 at half size), upsample, add, encode sRGB. PNG written with
compression level 1 (fxrun's fast setting)."""
import sys
import cv2
import numpy as np

src, dst = sys.argv[1], sys.argv[2]
img = cv2.imread(src, cv2.IMREAD_UNCHANGED)
if img.ndim == 2:
    img = cv2.cvtColor(img, cv2.COLOR_GRAY2BGR)
rgb = img[..., :3].astype(np.float32) / 255.0
lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4).astype(np.float32)
luma = lin @ np.array([0.0722, 0.7152, 0.2126], np.float32)  # BGR order
t, k = 0.7, 0.2
soft = np.clip(luma - t + k, 0, 2 * k)
contrib = np.maximum(soft * soft / (4 * k), luma - t)
bright = lin * (np.maximum(contrib, 0) / np.maximum(luma, 1e-5))[..., None]
h, w = lin.shape[:2]
half = cv2.resize(bright, ((w + 1) // 2, (h + 1) // 2), interpolation=cv2.INTER_AREA)
blur = cv2.GaussianBlur(half, (0, 0), 4, borderType=cv2.BORDER_REPLICATE)
up = cv2.resize(blur, (w, h), interpolation=cv2.INTER_LINEAR)
out = lin + up
enc = np.where(out <= 0.0031308, out * 12.92, 1.055 * np.power(np.maximum(out, 0), 1 / 2.4) - 0.055)
cv2.imwrite(dst, np.clip(enc * 255 + 0.5, 0, 255).astype(np.uint8), [cv2.IMWRITE_PNG_COMPRESSION, 1])
