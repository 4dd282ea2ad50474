#!/usr/bin/env python3
"""Gaussian blur sigma 8 with OpenCV (the reference fxgraph's gaussian_blur
matches within 1 LSB), PNG compression level 1."""
import sys
import cv2

img = cv2.imread(sys.argv[1], cv2.IMREAD_UNCHANGED)
out = cv2.GaussianBlur(img, (0, 0), float(sys.argv[3]) if len(sys.argv) > 3 else 8.0, borderType=cv2.BORDER_REPLICATE)
cv2.imwrite(sys.argv[2], out, [cv2.IMWRITE_PNG_COMPRESSION, 1])
