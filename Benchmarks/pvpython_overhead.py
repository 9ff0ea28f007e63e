"""pvpython's UpdatePipeline against the VTK filter's own Update, in one process (issue 14's
"pvpython time / kernel time" ratio): the generated 256x256x415 phantom, R = 10, best of 3.

    pvpython Benchmarks/pvpython_overhead.py "$(cat build/VolumetricAOPluginPath.txt)"
"""
import sys
import time

from paraview.simple import *  # noqa: F401,F403

LoadPlugin(sys.argv[1], ns=globals())
source = AmbientOcclusionHeadPhantom(Dimensions=[256, 256, 415])
source.UpdatePipeline()
for method in ["Gaussian CDF", "Histogram CDF", "CDF Reconstruction"]:
    through_paraview, filter_only = 1e9, 1e9
    for repeat in range(3):
        ao = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=10)
        start = time.time()
        ao.UpdatePipeline()
        through_paraview = min(through_paraview, time.time() - start)
        vtk_filter = ao.GetClientSideObject()
        vtk_filter.Modified()
        start = time.time()
        vtk_filter.Update()
        filter_only = min(filter_only, time.time() - start)
        Delete(ao)
    print("%-20s pvpython UpdatePipeline %7.1f ms, the VTK filter's Update %7.1f ms: ratio %.2f"
          % (method, through_paraview * 1e3, filter_only * 1e3, through_paraview / filter_only))
