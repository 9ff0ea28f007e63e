#!/usr/bin/python3
"""The peer of the variance occlusion map: scipy.ndimage blurring v and v^2 with the same
5-tap Gaussian (sigma 1 voxel, float64) as the pyramid's level 0, on the same volume; the
coarser levels are not counted. Prints `scipy_blur seconds`, the best of 3.

Usage: scipy_blur_peer.py VOLUME (a .raw file named *_NXxNYxNZ_int16.raw, or a .mha)"""
import os
import sys
import time

from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from scipy_peer import read_volume  # noqa: E402  (the same reader as the box-statistics peer)


def level_zero(volume):
    v = volume.astype("float64")
    mean = ndimage.gaussian_filter(v, sigma=1.0, truncate=2.0, mode="nearest")
    second = ndimage.gaussian_filter(v * v, sigma=1.0, truncate=2.0, mode="nearest")
    return mean, second


if __name__ == "__main__":
    volume = read_volume(sys.argv[1])
    best = 1e300
    for repeat in range(3):
        start = time.perf_counter()
        level_zero(volume)
        best = min(best, time.perf_counter() - start)
    print("scipy_blur %.4f" % best, flush=True)
