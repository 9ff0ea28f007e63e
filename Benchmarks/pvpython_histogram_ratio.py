"""Histogram CDF's time as a multiple of the Gaussian CDF's, on the kinds of volume users
bring, in one pvpython process (R = 10, 64 bins, the filter through UpdatePipeline):

- the scans in Data/ and in each DATA_DIR given (laid out like Data/): CT, MR, 8- and
  16-bit, whichever are there;
- the generated head phantom, 256x256x415 int16;
- a smooth random field (white noise averaged over 9x9x9 boxes), float32,
  256^3;
- white noise, int16 and float32, 256^3.

Each volume runs 5 rounds of the Gaussian CDF then Histogram CDF (this machine's speed
drifts within minutes; a round mostly does not); the median ratio of the rounds is
printed, with the median times.

    pvpython Benchmarks/pvpython_histogram_ratio.py "$(cat build/VolumetricAOPluginPath.txt)" [DATA_DIR ...]
"""
import os
import sys
import time

import numpy as np
from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData

LoadPlugin(sys.argv[1], ns=globals())
HERE = os.path.dirname(os.path.abspath(__file__))
FOLDERS = [os.path.join(HERE, "..", "Data")] + sys.argv[2:]
SCANS = ["ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", "lidc2_ct_chest/LIDC2_256x256x133_uint8.mha",
         "head_mr_small/HeadMRVolume.mhd", "headsq/headsq_64x64x93_int16.vti",
         "ct_head_phantom/ct_head_phantom_512x512x209_int16.mha", "engine/engine_256x256x128_uint8_zfp8.mha",
         "tooth/tooth.nhdr"]
ROUNDS = 5


def producer(values):
    image = vtkImageData()
    nz, ny, nx = values.shape
    image.SetDimensions(nx, ny, nz)
    array = numpy_to_vtk(values.reshape(-1), deep=1)
    array.SetName("values")
    image.GetPointData().SetScalars(array)
    source = PVTrivialProducer()
    source.GetClientSideObject().SetOutput(image)
    source.UpdatePipeline()
    return source


def box_blur(values, width):
    for axis in range(3):
        sums = np.cumsum(values, axis=axis, dtype=np.float64)
        sums = np.concatenate([np.zeros_like(np.take(sums, [0], axis=axis)), sums], axis=axis)
        n = values.shape[axis]
        hi = np.minimum(np.arange(n) + width // 2 + 1, n)
        lo = np.maximum(np.arange(n) - width // 2, 0)
        shape = [1, 1, 1]
        shape[axis] = n
        values = (np.take(sums, hi, axis=axis) - np.take(sums, lo, axis=axis)) / (hi - lo).reshape(shape)
    return values


def seconds(proxy):
    start = time.perf_counter()
    proxy.UpdatePipeline()
    return time.perf_counter() - start


def measure(name, source):
    source.UpdatePipeline()  # a generated volume is made before the timings
    times = {"Gaussian CDF": [], "Histogram CDF": []}
    for repeat in range(ROUNDS):
        for method in times:
            proxy = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=10, QueryMode="Voxel Value")
            times[method].append(seconds(proxy))
            Delete(proxy)
    ratios = sorted(h / g for g, h in zip(times["Gaussian CDF"], times["Histogram CDF"]))
    median = {m: sorted(t)[ROUNDS // 2] * 1e3 for m, t in times.items()}
    print("%-44s Gaussian %7.1f ms  Histogram %7.1f ms  ratio %.2f (%.2f-%.2f)"
          % (name, median["Gaussian CDF"], median["Histogram CDF"], ratios[ROUNDS // 2], ratios[0], ratios[-1]),
          flush=True)


volumes = []
for scan in SCANS:
    path = next((p for p in (os.path.join(f, scan) for f in FOLDERS) if os.path.exists(p)), None)
    if path:
        reader = OpenDataFile(path)
        reader.UpdatePipeline()
        info = reader.GetDataInformation()
        extent = info.GetExtent()
        array = info.GetPointDataInformation().GetArrayInformation(0)
        label = "%s %dx%dx%d %s" % (scan.split("/")[-1].split("_")[0].split(".")[0], extent[1] + 1,
                                    extent[3] + 1, extent[5] + 1, array.GetDataTypeAsString())
        volumes.append((label, reader))
volumes.append(("generated phantom 256x256x415 short", AmbientOcclusionHeadPhantom(Dimensions=[256, 256, 415])))
rng = np.random.default_rng(47)
noise = rng.random((256, 256, 256), dtype=np.float32)
volumes.append(("smooth random field 256^3 float", producer(box_blur(noise, 9).astype(np.float32))))
volumes.append(("white noise 256^3 short", producer((noise * 2000 - 1000).astype(np.int16))))
volumes.append(("white noise 256^3 float", producer(noise)))
for name, source in volumes:
    measure(name, source)
