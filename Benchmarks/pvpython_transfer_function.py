"""Transfer Function AO, Rays and Exact Rays against the Gaussian CDF, in one pvpython
process, and the time to follow an edit of the opacity transfer function:

- Volumetric AO, R = 10, on the generated 256x256x415 int16 phantom: the Gaussian CDF and
  the Transfer Function method run one after the other in each round (this machine's
  speed drifts within minutes; a round mostly does not), 5 rounds, the median ratio;
- a 128^3 phantom, R = 10: the opacity's points edited (as the Color Map Editor does), then
  UpdatePipeline; the time of that update, which re-executes the filter only;
- the 128^3 phantom, R = 10, the same opacity: Rays and the Gaussian CDF alternating in 3
  rounds (the median ratio), and Exact Rays (128 rays) on 4 of its slices, extrapolated.

    pvpython Benchmarks/pvpython_transfer_function.py "$(cat build/VolumetricAOPluginPath.txt)"
"""
import sys
import time

from paraview.simple import *  # noqa: F401,F403

LoadPlugin(sys.argv[1], ns=globals())
ROUNDS = 5


def seconds(update):
    start = time.perf_counter()
    update()
    return time.perf_counter() - start


def median(values):
    return sorted(values)[len(values) // 2]


# A CT preset with the bone transparent: air 0, soft tissue shown, bone (above 300 HU) 0.
TISSUE = [-1000.0, 0.0, 0.5, 0.0, -200.0, 0.3, 0.4, 0.6, 250.0, 0.3, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0]
body = AmbientOcclusionHeadPhantom(Dimensions=[256, 256, 415])
body.UpdatePipeline()
opacity = GetOpacityTransferFunction("Density")
opacity.Points = TISSUE
times = {"Gaussian CDF": [], "Transfer Function": []}
ratios = []
for repeat in range(ROUNDS):
    for method in times:
        extra = {"OpacityFunction": opacity} if method == "Transfer Function" else {}
        proxy = VolumetricAmbientOcclusion(Input=body, Method=method, Radius=10, QueryMode="Voxel Value", **extra)
        times[method].append(seconds(proxy.UpdatePipeline))
        Delete(proxy)
    ratios.append(times["Transfer Function"][-1] / times["Gaussian CDF"][-1])
print("256x256x415 int16, R = 10, %d rounds: Gaussian CDF median %.0f ms, Transfer Function median %.0f ms"
      % (ROUNDS, median(times["Gaussian CDF"]) * 1e3, median(times["Transfer Function"]) * 1e3))
print("  Transfer Function / Gaussian CDF, round by round: median %.2fx (%.2f-%.2f)"
      % (median(ratios), min(ratios), max(ratios)))
Delete(body)

small = AmbientOcclusionHeadPhantom(Dimensions=[128, 128, 128])
ao = VolumetricAmbientOcclusion(Input=small, Method="Transfer Function", Radius=10, OpacityFunction=opacity)
ao.UpdatePipeline()
edits = []
for repeat in range(10):
    points = list(TISSUE)
    points[5] = 0.2 + 0.05 * (repeat % 5)  # the soft tissue's opacity, as a drag in the editor
    opacity.Points = points
    edits.append(seconds(ao.UpdatePipeline))
print("128^3 int16, R = 10, an opacity edit then UpdatePipeline (10 edits): median %.1f ms, best %.1f ms"
      % (median(edits) * 1e3, min(edits) * 1e3))

# The rays through the same opacity, against the Gaussian CDF on the same volume.
rays_times, gaussian_times, ray_ratios = [], [], []
for repeat in range(3):
    for method, store in (("Gaussian CDF", gaussian_times), ("Rays", rays_times)):
        extra = {"OpacityFunction": opacity} if method == "Rays" else {}
        proxy = VolumetricAmbientOcclusion(Input=small, Method=method, Radius=10, QueryMode="Voxel Value", **extra)
        store.append(seconds(proxy.UpdatePipeline))
        Delete(proxy)
    ray_ratios.append(rays_times[-1] / gaussian_times[-1])
print("128^3 int16, R = 10: Gaussian CDF median %.0f ms, Rays median %.0f ms; Rays / Gaussian CDF median %.0fx"
      % (median(gaussian_times) * 1e3, median(rays_times) * 1e3, median(ray_ratios)))
slab = ExtractSubset(Input=small, VOI=[0, 127, 0, 127, 62, 65])
exact = VolumetricAmbientOcclusion(Input=slab, Method="Exact Rays", Radius=10, OpacityFunction=opacity)
slab.UpdatePipeline()
exact_seconds = seconds(exact.UpdatePipeline) * 128 / 4
print("  Exact Rays (128 rays), 4 slices extrapolated to 128^3: %.1f s, %.0fx the Gaussian CDF"
      % (exact_seconds, exact_seconds / median(gaussian_times)))
