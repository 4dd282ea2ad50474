#!/usr/bin/env python3
"""Gaussian blur sigma 8 with PyTorch on the GPU when it has one (CUDA), as two
separable conv2d passes with the kernel OpenCV uses for sigma 8 (size
round(8 sigma + 1) | 1, replicate borders); PNG in and out through OpenCV at
compression level 1. The whole process is what bench/gpu.sh times: import,
decode, upload, blur, download, encode."""
import sys

import cv2
import numpy as np
import torch

src, dst = sys.argv[1], sys.argv[2]
sigma = float(sys.argv[3]) if len(sys.argv) > 3 else 8.0
img = cv2.imread(src, cv2.IMREAD_UNCHANGED)
dev = "cuda" if torch.cuda.is_available() else "cpu"
x = torch.from_numpy(img).to(dev).permute(2, 0, 1).unsqueeze(0).float()
size = int(round(sigma * 8 + 1)) | 1
k = cv2.getGaussianKernel(size, sigma).astype(np.float32).ravel()
k = torch.from_numpy(k).to(dev)
c = x.shape[1]
pad = size // 2
x = torch.nn.functional.pad(x, (pad, pad, 0, 0), mode="replicate")
x = torch.nn.functional.conv2d(x, k.view(1, 1, 1, size).repeat(c, 1, 1, 1), groups=c)
x = torch.nn.functional.pad(x, (0, 0, pad, pad), mode="replicate")
x = torch.nn.functional.conv2d(x, k.view(1, 1, size, 1).repeat(c, 1, 1, 1), groups=c)
out = x.squeeze(0).permute(1, 2, 0).round().clamp(0, 255).to(torch.uint8).cpu().numpy()
cv2.imwrite(dst, out, [cv2.IMWRITE_PNG_COMPRESSION, 1])
