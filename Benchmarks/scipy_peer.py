#!/usr/bin/python3
"""The peer of the benchmark: scipy.ndimage computing the same box statistics as
VolumetricAO (mean and mean of squares by uniform_filter, minimum_filter, maximum_filter)
on the same volume. Prints one line per radius: `scipy R seconds`.

Usage: scipy_peer.py VOLUME R [R ...]
VOLUME: a .raw file named *_NXxNYxNZ_int16.raw, or a MetaImage .mha (zlib or raw)."""
import re
import sys
import time
import zlib

import numpy as np
from scipy import ndimage


def read_volume(path):
    if path.endswith(".raw"):
        nx, ny, nz = (int(v) for v in re.search(r"_(\d+)x(\d+)x(\d+)_int16\.raw$", path).groups())
        return np.fromfile(path, dtype="<i2").reshape(nz, ny, nx)
    with open(path, "rb") as f:
        blob = f.read()
    header_end = blob.index(b"ElementDataFile = LOCAL") + len(b"ElementDataFile = LOCAL")
    header = blob[:header_end].decode("ascii")
    payload = blob[header_end:].lstrip(b"\r\n")
    dims = [int(v) for v in re.search(r"DimSize = (\d+) (\d+) (\d+)", header).groups()]
    types = {"MET_SHORT": "<i2", "MET_USHORT": "<u2", "MET_UCHAR": "u1", "MET_FLOAT": "<f4"}
    dtype = types[re.search(r"ElementType = (\w+)", header).group(1)]
    if re.search(r"CompressedData = True", header):
        payload = zlib.decompress(payload)
    return np.frombuffer(payload, dtype=dtype).reshape(dims[2], dims[1], dims[0])


def statistics(volume, radius):
    size = 2 * radius + 1
    v = volume.astype(np.float64)
    mean = ndimage.uniform_filter(v, size=size, mode="constant")
    mean_sq = ndimage.uniform_filter(v * v, size=size, mode="constant")
    lo = ndimage.minimum_filter(volume, size=size, mode="nearest")
    hi = ndimage.maximum_filter(volume, size=size, mode="nearest")
    return mean, mean_sq, lo, hi


if __name__ == "__main__":
    volume = read_volume(sys.argv[1])
    for radius in (int(r) for r in sys.argv[2:]):
        start = time.perf_counter()
        statistics(volume, radius)
        print("scipy %d %.4f" % (radius, time.perf_counter() - start), flush=True)
