"""pvbatch (serial or under mpirun): read a .vti (ParaView's decomposition: each rank's
reader reads the sub-extent asked of it) or a .pvti written in pieces (a partitioned
reader), chain every image filter of the plugin, write a .pvti (one piece per rank).

Pass-through loggers write, per rank, the extent the filters received from upstream
(<OUT>.local.<rank>, <OUT>.sweeping.<rank>, <OUT>.piece.<rank>), for the test to check
that no rank received the whole volume. Usage: pvbatch mpi_run.py PLUGIN INPUT OUT.pvti"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import XML_OPTIONS, extent_logger  # noqa: E402

plugin, input_path, target = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())


def open_reader():
    reader = XMLPartitionedImageDataReader(FileName=[input_path]) if input_path.endswith(".pvti") else \
        XMLImageDataReader(FileName=[input_path])
    reader.PointArrayStatus = ["MetaImage"]
    return reader


reader = open_reader()
current = extent_logger(reader, target + ".local")
# Local filters: each rank needs its piece grown by the radius (10 + 5 + 7 + 2 = 24 voxels
# for the chain).
stages = [("Gaussian CDF", 10, "GaussianCDF"), ("CDF Reconstruction", 5, "CDFReconstruction"),
          ("Chebyshev", 7, "Chebyshev"), ("Exact Box", 2, "ExactBox")]
for method, radius, name in stages:
    current = VolumetricAmbientOcclusion(Input=current, Method=method, Radius=radius, QueryMode="Voxel Value",
                                         OutputArrayName=name, ComputeVariance=(name == "GaussianCDF"))
    current.Scalars = ["POINTS", "MetaImage"]
# Occlusion sweeping is global: each rank sweeps a slab (plus one ghost layer) and the
# slabs exchange faces until they agree; converged, so that serial runs agree too.
current = OcclusionSweeping(Input=extent_logger(current, target + ".sweeping"), IsoValue=400.0, NumberOfIterations=50,
                            ConvergenceTolerance=1e-4)
current.Scalars = ["POINTS", "MetaImage"]
current = AmbientOcclusionShading(Input=current, AmbientOcclusionArray="GaussianCDF")
current.Scalars = ["POINTS", "MetaImage"]
SaveData(target, proxy=current, **XML_OPTIONS)

# A local filter asked directly for the writer's pieces (ParaView's decomposition of the
# output, with ghost levels grown by the radius): each rank needs its piece + 10 voxels.
direct = VolumetricAmbientOcclusion(Input=extent_logger(reader, target + ".piece"), Method="Gaussian CDF", Radius=10,
                                    QueryMode="Voxel Value", OutputArrayName="Direct")
direct.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_direct.pvti", proxy=direct, **XML_OPTIONS)

# Histogram CDF takes its thresholds from the whole data set: the ranks reduce the value
# histograms of their pieces, so each still needs only its piece grown by the radii
# (5 + the smoothed query's window of 6 = 11 voxels).
histogram = VolumetricAmbientOcclusion(Input=extent_logger(reader, target + ".histogram"), Method="Histogram CDF",
                                       Radius=5, QueryMode="Voxel Value", OutputArrayName="Histogram")
histogram.Scalars = ["POINTS", "MetaImage"]
smoothed = VolumetricAmbientOcclusion(Input=histogram, Method="Histogram CDF", Radius=3, NumberOfBins=40,
                                      QueryMode="Smoothed Voxel Value", QuerySmoothing=2.0,
                                      OutputArrayName="HistogramSmoothed")
smoothed.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_histogram.pvti", proxy=smoothed, **XML_OPTIONS)

# Transfer Function AO: the opacity transfer function is the one ParaView keeps for the
# array (as the GUI's Color Map Editor edits it); each rank needs its piece grown by R
# (a reader of its own: the shared one keeps the largest extent any branch asked of it).
opacity = GetOpacityTransferFunction("MetaImage")
opacity.Points = [-1000.0, 0.0, 0.5, 0.0, -200.0, 0.2, 0.4, 0.6, 400.0, 0.6, 0.5, 0.0, 1500.0, 1.0, 0.5, 0.0]
transfer = VolumetricAmbientOcclusion(Input=extent_logger(open_reader(), target + ".tf"), Method="Transfer Function",
                                      Radius=6, OpacityFunction=opacity, OutputArrayName="TransferFunction")
transfer.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_tf.pvti", proxy=transfer, **XML_OPTIONS)

# Exact Rays through the same function: each rank needs its piece grown by the rays' reach
# (R = 2 voxels of the smallest spacing, 3.9 mm: 2 voxels along every axis).
rays = VolumetricAmbientOcclusion(Input=extent_logger(open_reader(), target + ".rays"), Method="Exact Rays",
                                  Radius=2, RayCount=16, OpacityFunction=opacity, OutputArrayName="ExactRays")
rays.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_rays.pvti", proxy=rays, **XML_OPTIONS)

# Rays through the same function: its cones read 4 voxels along every axis at R = 2 voxels
# (2 lattice steps, the blur's cell and the cell mean's neighbour).
fast = VolumetricAmbientOcclusion(Input=extent_logger(open_reader(), target + ".fastrays"), Method="Rays",
                                  Radius=2, OpacityFunction=opacity, OutputArrayName="Rays")
fast.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_fastrays.pvti", proxy=fast, **XML_OPTIONS)
