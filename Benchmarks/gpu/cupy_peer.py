#!/usr/bin/env python3
"""The GPU peer of vao_gpu_benchmark: cupyx.scipy.ndimage computing the same box
statistics as VolumetricAO (mean and mean of squares by uniform_filter in float64, like
../scipy_peer.py, minimum_filter and maximum_filter) on the same volume, already on the
device. Timed with CUDA events: best of --repeat runs after one warm-up (which also
compiles cupy's kernels). Prints one line per radius: `cupy <label> <R> <ms>`, where
label is <NX>x<NY>x<NZ>_<type> from the file name.

Without cupy (or without a device) it prints `cupy not available: <error>` and exits 0.

Usage: cupy_peer.py /tmp/vao_gpu_<NX>x<NY>x<NZ>_<int16|float32>.raw R [R ...] [--repeat N]
"""
import argparse
import math
import re
import sys

DTYPES = {"int16": "<i2", "float32": "<f4"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("volume")
    parser.add_argument("radii", type=int, nargs="+")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    match = re.search(r"_(\d+)x(\d+)x(\d+)_(int16|float32)\.raw$", args.volume)
    if not match:
        print("cupy_peer: cannot read the size and type from %s" % args.volume)
        return 2
    nx, ny, nz = (int(v) for v in match.groups()[:3])
    type_name = match.group(4)
    label = "%dx%dx%d_%s" % (nx, ny, nz, type_name)

    try:
        import numpy as np
        import cupy as cp
        from cupyx.scipy import ndimage

        if cp.cuda.runtime.getDeviceCount() < 1:
            raise RuntimeError("no CUDA device")
    except Exception as error:  # ImportError, CUDA driver or runtime errors
        print("cupy not available: %s: %s" % (type(error).__name__, error))
        return 0

    def statistics(volume, radius):
        size = 2 * radius + 1
        v = volume.astype(cp.float64)
        mean = ndimage.uniform_filter(v, size=size, mode="constant")
        mean_sq = ndimage.uniform_filter(v * v, size=size, mode="constant")
        lo = ndimage.minimum_filter(volume, size=size, mode="nearest")
        hi = ndimage.maximum_filter(volume, size=size, mode="nearest")
        return mean, mean_sq, lo, hi

    try:
        host = np.fromfile(args.volume, dtype=DTYPES[type_name])
        if host.size != nx * ny * nz:
            print("cupy_peer: %s holds %d voxels, not %d" % (args.volume, host.size, nx * ny * nz))
            return 2
        volume = cp.asarray(host.reshape(nz, ny, nx))
        for radius in args.radii:
            statistics(volume, radius)  # warm-up: compiles and caches the kernels
            cp.cuda.Device().synchronize()
            best = math.inf
            for _ in range(max(1, args.repeat)):
                start, end = cp.cuda.Event(), cp.cuda.Event()
                start.record()
                result = statistics(volume, radius)
                end.record()
                end.synchronize()
                best = min(best, cp.cuda.get_elapsed_time(start, end))
                del result
            print("cupy %s %d %.4f" % (label, radius, best), flush=True)
            cp.get_default_memory_pool().free_all_blocks()
    except Exception as error:  # e.g. NVRTC or out of memory: report, do not fail the run
        print("cupy failed: %s: %s" % (type(error).__name__, error))
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
