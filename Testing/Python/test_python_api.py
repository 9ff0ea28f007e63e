"""The numpy functions of volumetricao as Python code should behave (python3 or pvpython):
scipy's sampling and vtkImageData input, dtypes converted, Python's exceptions with the
filter's own sentence (no VTK file, line or address), the filters' warnings as
VolumetricAOWarning and nothing on stderr, backend/threads/return_info, progress.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_python_api.py SITE_PACKAGES_DIR"""
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import warnings

site = sys.argv[1]
sys.path.insert(0, site)
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from volumetricao import VolumetricAOWarning  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPiecewiseFunction, vtkPolyData  # noqa: E402
from vtkmodules.vtkImagingCore import vtkImageCast  # noqa: E402

from vao_test_utils import check, finish, same  # noqa: E402


# pvpython's sys.executable names a vtkpython that is not installed: run pvpython itself.
INTERPRETER = sys.executable if os.path.exists(sys.executable) else shutil.which("pvpython")


def run_python(code):
    """stdout and stderr of `code` run by this interpreter with the package on the path."""
    env = dict(os.environ, PYTHONPATH=site + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with tempfile.TemporaryDirectory() as folder:
        script = os.path.join(folder, "script.py")
        with open(script, "w") as f:
            f.write(code)
        done = subprocess.run([INTERPRETER, script], capture_output=True, text=True, env=env, timeout=120)
    return done.returncode, done.stdout, done.stderr


rng = np.random.default_rng(4)
int16 = (rng.integers(-300, 900, size=(14, 17, 19)) // 50 * 50).astype(np.int16)
smooth = np.cumsum(np.cumsum(rng.normal(size=(16, 18, 20)), axis=0), axis=2).astype(np.float32)
sampling = (2.0, 0.5, 1.0)

# Input forms: vtkImageData, an algorithm and its output port, 4-D arrays with a component.
image = vtkImageData()
image.SetDimensions(20, 18, 16)
image.SetSpacing(*reversed(sampling))
image.SetOrigin(5.0, -3.0, 1.0)
for name, values in (("other", -smooth), ("smooth", smooth)):
    array = numpy_to_vtk(values.reshape(-1), deep=1)
    array.SetName(name)
    image.GetPointData().AddArray(array)
image.GetPointData().SetActiveScalars("smooth")
reference = volumetricao.ambient_occlusion(smooth, radius=3.0, world_radius=True, sampling=sampling)
check(same(volumetricao.ambient_occlusion(image, radius=3.0, world_radius=True), reference),
      "vtkImageData: its spacing and active scalars are used, the result is [z, y, x]")
check(same(volumetricao.ambient_occlusion(image, radius=3.0, world_radius=True, scalars="other"),
           volumetricao.ambient_occlusion(-smooth, radius=3.0, world_radius=True, sampling=sampling)),
      "vtkImageData: scalars= names another point array")
cast = vtkImageCast()
cast.SetInputData(image)
cast.SetOutputScalarTypeToFloat()
check(same(volumetricao.ambient_occlusion(cast, radius=3.0, world_radius=True), reference)
      and same(volumetricao.ambient_occlusion(cast.GetOutputPort(), radius=3.0, world_radius=True), reference),
      "an algorithm, or its output port, whose output is image data")
stacked = np.stack([-smooth, smooth], axis=-1)
check(same(volumetricao.ambient_occlusion(stacked, radius=2, component=1),
           volumetricao.ambient_occlusion(smooth, radius=2))
      and same(volumetricao.occlusion_sweeping(stacked, 0.0, component=1)[1],
               volumetricao.occlusion_sweeping(smooth, 0.0)[1]),
      "a 4-D array [z, y, x, c] with component= is that component's volume")
check(same(volumetricao.ambient_occlusion(smooth, radius=3.0, world_radius=True, sampling=1.5),
           volumetricao.ambient_occlusion(smooth, radius=3.0, world_radius=True, sampling=(1.5, 1.5, 1.5))),
      "a scalar sampling is the same on every axis")
local = np.array([[8 * 2.0, 9 * 0.5, 10.0], [3 * 2.0, 4.25, 7.5]])       # (z, y, x) from the first voxel
world = local + (1.0, -3.0, 5.0)                                          # plus the origin, in (z, y, x)
on_image = volumetricao.isosurface_ambient_occlusion(image, world, shadows=True)
on_array = volumetricao.isosurface_ambient_occlusion(smooth, local, sampling=sampling, shadows=True)
check(all(np.allclose(a, b, rtol=0, atol=1e-6) for a, b in zip(on_image, on_array)),
      "isosurface AO on a vtkImageData: vertices in its world coordinates (z, y, x), its origin included")

# Other byte orders, float16 and bool are converted: the result is the native array's.
for what, other, native, level in [(">i2 (big-endian)", int16.astype(">i2"), int16, 50),
                                   (">f8 (big-endian)", int16.astype(">f8"), int16.astype(np.float64), 50),
                                   ("float16", int16.astype(np.float16), int16.astype(np.float16).astype(np.float32),
                                    50),
                                   ("bool", int16 > 100, (int16 > 100).astype(np.uint8), 0.5),
                                   ("a non-contiguous view", int16[:, ::2, 1:], int16[:, ::2, 1:].copy(), 50)]:
    distance = volumetricao.occlusion_sweeping(other, level)[1]
    check(same(volumetricao.ambient_occlusion(other, radius=2, method="Gaussian CDF"),
               volumetricao.ambient_occlusion(native, radius=2, method="Gaussian CDF"))
          and same(distance, volumetricao.occlusion_sweeping(native, level)[1])
          and (distance < 0).any() and (distance > 0).any(),
          "%s: equals the native array's AO and sweeping" % what)


# method="transfer function": 1 - the mean opacity over the box clipped to the volume. The
# reference: np.interp is VTK's clamped linear interpolation for default midpoints and
# sharpness; the box mean by brute force.
points = [(-200, 0.0), (100, 0.9), (400, 0.2), (600, 0.0)]
alpha = np.interp(int16.astype(np.float64), *zip(*points))
expected = np.empty_like(alpha)
for z, y, x in np.ndindex(*alpha.shape):
    expected[z, y, x] = 1 - alpha[max(z - 2, 0):z + 3, max(y - 2, 0):y + 3, max(x - 2, 0):x + 3].mean()
shown = volumetricao.ambient_occlusion(int16, radius=2, method="Transfer_Function", opacity=points)
check(shown.dtype == np.float32 and np.abs(shown - expected).max() <= 1e-6,
      "transfer function from (N, 2) points equals 1 - the box mean of the opacity (max difference %.3g)"
      % np.abs(shown - expected).max())
function = vtkPiecewiseFunction()
for value, opacity in points:
    function.AddPoint(value, opacity, 0.5, 0.0)
flat = [v for value, opacity in points for v in (value, opacity, 0.5, 0.0)]
check(same(volumetricao.ambient_occlusion(int16, radius=2, method="transfer function", opacity=function), shown)
      and same(volumetricao.ambient_occlusion(int16, radius=2, method="transfer function", opacity=flat), shown),
      "a vtkPiecewiseFunction and ParaView's flat Points give the same transfer-function AO")
# Exceptions: the filter's sentence, no decoration.
vertices = np.array([[5.0, 5.0, 5.0]])
errors = [
    ("radius 0", lambda: volumetricao.ambient_occlusion(int16, radius=0), ValueError, "Radius 0 rounds to 0 voxels"),
    ("NaN voxels", lambda: volumetricao.ambient_occlusion(np.full((5, 5, 5), np.nan, np.float32), radius=1),
     ValueError, "NaN"),
    ("a 2-D image", lambda: volumetricao.ambient_occlusion(int16[:1]), ValueError, "needs a 3-D volume"),
    ("threads -1", lambda: volumetricao.occlusion_sweeping(int16, 0, threads=-1), ValueError, "NumberOfThreads"),
    ("opacity 2", lambda: volumetricao.occlusion_sweeping(int16, 0, opacity=2), ValueError, "opacity must lie"),
    ("levels 0", lambda: volumetricao.variance_occlusion_map(int16, levels=0), ValueError, "pyramid levels"),
    ("a vertex outside", lambda: volumetricao.isosurface_ambient_occlusion(int16, vertices * 10), ValueError,
     "The surface reaches outside the volume"),
    ("gamma 0", lambda: volumetricao.shade(int16, int16 * 0.0, gamma=0), ValueError, "Gamma must be"),
    ("complex values", lambda: volumetricao.ambient_occlusion(int16.astype(np.complex64)), ValueError, "complex"),
    ("an object array", lambda: volumetricao.ambient_occlusion(int16.astype(object)), ValueError, "numeric"),
    ("an unknown method", lambda: volumetricao.ambient_occlusion(int16, method="Fast"), ValueError, "unknown method"),
    ("a 2-D array", lambda: volumetricao.ambient_occlusion(np.zeros((4, 4))), ValueError, "3-D array"),
    ("sampling of 2 values", lambda: volumetricao.ambient_occlusion(int16, sampling=(1, 2)), ValueError, "sampling"),
    ("backend 'gpu'", lambda: volumetricao.ambient_occlusion(int16, backend="gpu"), ValueError, "backend"),
    ("normals of another count", lambda: volumetricao.isosurface_ambient_occlusion(int16, vertices, np.ones((2, 3))),
     ValueError, "one row per vertex"),
    ("vertices (N, 2)", lambda: volumetricao.isosurface_ambient_occlusion(int16, np.ones((3, 2))), ValueError,
     "(N, 3)"),
    ("an AO of another shape", lambda: volumetricao.shade(int16, int16[1:] * 0.0), ValueError, "shape"),
    ("threads 1.5", lambda: volumetricao.ambient_occlusion(int16, threads=1.5), TypeError, "integer"),
    ("a string volume", lambda: volumetricao.ambient_occlusion("head.mha"), TypeError, "numpy array"),
    ("a surface as the volume", lambda: volumetricao.ambient_occlusion(vtkPolyData()), TypeError, "image data"),
    ("method='transfer function' without opacity",
     lambda: volumetricao.ambient_occlusion(int16, method="transfer function"), ValueError, "needs opacity"),
    ("opacity with another method", lambda: volumetricao.ambient_occlusion(int16, opacity=[(0, 1)]), ValueError,
     "opacity is used by"),
    ("opacity points (N, 3)", lambda: volumetricao.ambient_occlusion(int16, method="transfer function",
                                                                   opacity=np.ones((2, 3))), ValueError, "(N, 2)"),
    ("an opacity of 1.5", lambda: volumetricao.ambient_occlusion(int16, method="transfer function",
                                                                opacity=[(0, 0), (10, 1.5)]), ValueError, "[0, 1]"),
    ("a NaN opacity point", lambda: volumetricao.ambient_occlusion(int16, method="transfer function",
                                                                  opacity=[(np.nan, 0)]), ValueError, "finite"),
    ("an empty vtkPiecewiseFunction", lambda: volumetricao.ambient_occlusion(
        int16, method="transfer function", opacity=vtkPiecewiseFunction()), ValueError, "no points"),
    ("sampling with a vtkImageData", lambda: volumetricao.ambient_occlusion(image, sampling=1.0), TypeError,
     "own spacing"),
]
for what, call, error, words in errors:
    try:
        call()
        check(False, "%s raises %s" % (what, error.__name__))
    except error as e:
        text = str(e)
        check(words in text and "ERROR: In" not in text and ".cxx" not in text and "(0x" not in text,
              "%s raises %s with the sentence alone: %s" % (what, error.__name__, text[:110]))
    except Exception as e:  # noqa: BLE001
        check(False, "%s raises %s, not %s: %s" % (what, error.__name__, type(e).__name__, e))

# A computation that fails raises RuntimeError: a memory limit below what the output needs.
code = r"""
import resource, numpy as np, volumetricao
values = np.zeros((200, 200, 200), np.float32)
values[::2] = 1
size = [int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmSize")][0]
resource.setrlimit(resource.RLIMIT_AS, (size + 40 * 2 ** 20, resource.RLIM_INFINITY))
try:
    volumetricao.ambient_occlusion(values, radius=2, threads=1, backend="cpu")
except RuntimeError as e:
    print("RuntimeError:", e)
"""
rc, out, err = run_python(code)
check("RuntimeError: Not enough memory" in out and ".cxx" not in out,
      "out of memory raises RuntimeError with the filter's sentence: %s" % (out.strip() or err.strip())[:120])

# Warnings: caught as VolumetricAOWarning, pointing at the caller; nothing on stderr.
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    volumetricao.occlusion_sweeping(int16, 5000.0)
check(len(caught) == 1 and caught[0].category is VolumetricAOWarning and issubclass(VolumetricAOWarning, UserWarning)
      and str(caught[0].message).startswith("IsoValue 5000 does not cross") and caught[0].filename == __file__,
      "a filter warning arrives through warnings.warn as VolumetricAOWarning, at the caller's line: %s"
      % [(w.category.__name__, str(w.message)[:60], os.path.basename(w.filename)) for w in caught])
with warnings.catch_warnings():
    warnings.simplefilter("error", VolumetricAOWarning)
    try:
        volumetricao.occlusion_sweeping(int16, 5000.0)
        check(False, "warnings.simplefilter('error', VolumetricAOWarning) makes the warning an exception")
    except VolumetricAOWarning:
        check(True, "warnings.simplefilter('error', VolumetricAOWarning) makes the warning an exception")
code = r"""
import warnings, numpy as np, volumetricao
warnings.simplefilter("ignore")
values = np.zeros((8, 8, 8), np.int16)
volumetricao.occlusion_sweeping(values, 3.0)
volumetricao.variance_occlusion_map(values, backend="cuda")
try:
    volumetricao.ambient_occlusion(values, radius=0)
except ValueError:
    print("raised")
"""
rc, out, err = run_python(code)
check(rc == 0 and out.strip() == "raised" and err == "",
      "warnings ignored and an error raised print nothing on stderr (stderr %r)" % err[:200])

# Backend, threads and what ran.
for name, call, pick in (
        ("occlusion_sweeping", lambda **k: volumetricao.occlusion_sweeping(int16, 50, **k), lambda r: r[0]),
        ("variance_occlusion_map", lambda **k: volumetricao.variance_occlusion_map(int16, **k), lambda r: r[0].mean),
        ("isosurface_ambient_occlusion",
         lambda **k: volumetricao.isosurface_ambient_occlusion(smooth, np.array([[8.0, 9.0, 10.0]]), **k),
         lambda r: r),
        ("shade", lambda **k: volumetricao.shade(smooth, np.ones_like(smooth), **k), lambda r: r)):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cuda, info = call(backend="cuda", threads=1, return_info=True)
    check(same(pick(cuda), pick(call(backend="cpu", threads=2))) and info == volumetricao.RunInfo("CPU", "CPU", None)
          and [w.category for w in caught] == [VolumetricAOWarning] and "no CUDA backend" in str(caught[0].message),
          "%s: backend='cuda' warns and runs on the CPU, equal for any threads; info %s" % (name, info))
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    ao, info = volumetricao.ambient_occlusion(int16, radius=2, method="Exact Box", backend="cuda", return_info=True)
cpu, cpu_info = volumetricao.ambient_occlusion(int16, radius=2, method="Exact Box", backend="cpu", threads=3,
                                               return_info=True)
ran_cuda = info.backend == "CUDA"
check(same(ao, cpu) and cpu_info == volumetricao.RunInfo("CPU", "CPU", 3)
      and (ran_cuda or [w.category for w in caught] == [VolumetricAOWarning]),
      "ambient_occlusion: backend='cuda' ran %s (%s; warnings %s), equal to the CPU's; threads=3 reported"
      % (info.backend, info, [str(w.message)[:70] for w in caught]))

carrier = vtkImageData()
carrier.DeepCopy(image)
ran_before = volumetricao.vtkVolumetricAmbientOcclusion()
ran_before.SetInputData(carrier)
ran_before.SetRadius(2)
ran_before.Update()                         # its output's field data says what ran upstream
colours, info = volumetricao.shade(ran_before.GetOutput(), return_info=True)
check(info == volumetricao.RunInfo("CPU", "CPU", None) and colours.shape == smooth.shape + (4,),
      "shade of a Volumetric AO output reports its own run, not the upstream filter's (%s)" % (info,))

# Progress: a callable sees the fraction rise to 1, in steps of at most 5% on one thread
# (there the steps depend on the work alone; across threads, on these runs of milliseconds,
# on how the threads were scheduled: Benchmarks/progress_steps.py measures long runs);
# progress=True draws a bar on stderr.
steps = np.random.default_rng(5).normal(size=(48, 64, 80)).astype(np.float32)
surface_points = np.stack(np.meshgrid(np.arange(24.0), np.linspace(8, 56, 40), np.arange(10.0, 70.0),
                                      indexing="ij"), -1).reshape(-1, 3)
surface_normals = np.tile([1.0, 0.0, 0.0], (len(surface_points), 1))
for threads in (1, 0):
    for name, call in (
            ("ambient_occlusion", lambda p: volumetricao.ambient_occlusion(steps, radius=3, threads=threads,
                                                                           progress=p)),
            ("ambient_occlusion Gaussian CDF", lambda p: volumetricao.ambient_occlusion(
                steps, radius=3, method="gaussian cdf", threads=threads, progress=p)),
            ("ambient_occlusion smoothed", lambda p: volumetricao.ambient_occlusion(
                steps, radius=3, query_smoothing=1.5, threads=threads, progress=p)),
            ("ambient_occlusion Transfer Function", lambda p: volumetricao.ambient_occlusion(
                steps, radius=3, method="transfer function", opacity=[(0, 0), (1, 1)], threads=threads,
                progress=p)),
            ("occlusion_sweeping", lambda p: volumetricao.occlusion_sweeping(steps, 0.0, threads=threads,
                                                                             progress=p)),
            ("variance_occlusion_map", lambda p: volumetricao.variance_occlusion_map(steps, threads=threads,
                                                                                     progress=p)),
            ("isosurface_ambient_occlusion", lambda p: volumetricao.isosurface_ambient_occlusion(
                steps, surface_points, surface_normals, iso_value=0.0, threads=threads, progress=p)),
            ("shade", lambda p: volumetricao.shade(steps, np.ones_like(steps), threads=threads, progress=p))):
        seen = []
        call(seen.append)
        rises = [0.0] + seen
        gap = max(b - a for a, b in zip(rises, rises[1:]))
        check(len(seen) >= 3 and seen == sorted(seen) and seen[-1] == 1.0 and (gap <= 0.05 or not threads),
              "%s, threads=%d: progress called %d times, rising to 1, largest step %.3f"
              % (name, threads, len(seen), gap))
bar = "import numpy as np, volumetricao\nvolumetricao.ambient_occlusion(np.ones((9, 9, 9)), radius=2, progress=True)\n"
rc, out, err = run_python("import sys; sys.modules['tqdm'] = None\n" + bar)
check(rc == 0 and "ambient_occlusion [####################] 100%" in err and "\x1b[" not in err,
      "progress=True without tqdm: a plain bar on stderr (%r)" % err[-60:])
if importlib.util.find_spec("tqdm") is not None:
    rc, out, err = run_python(bar)
    check(rc == 0 and "100%" in err and "ambient_occlusion" in err, "progress=True with tqdm: tqdm's bar (%r)"
          % err.strip()[-70:])
else:
    print("skipped: tqdm is not installed, its bar is not checked")

# Results are the filters' own arrays, not copies: writable, each holding its memory while
# later runs take the blocks that earlier, discarded results left (outputs of 2 MiB and
# more are kept for the next output of their size).
import gc  # noqa: E402

large = (rng.integers(-300, 900, size=(64, 96, 96)) // 50 * 50).astype(np.int16)
held = volumetricao.ambient_occlusion(large, radius=2, method="gaussian cdf")
finest = volumetricao.variance_occlusion_map(large, levels=2)[0]
held_mean, held_variance = finest.mean, finest.variance
before = [held.copy(), held_mean.copy(), held_variance.copy()]
for shift in (100, 200, 300):
    volumetricao.ambient_occlusion(large + shift, radius=2, method="gaussian cdf")
    volumetricao.variance_occlusion_map(large - shift, levels=2)
    gc.collect()
again = volumetricao.ambient_occlusion(large, radius=2, method="gaussian cdf")
check(all(same(a, b) for a, b in zip([held, held_mean, held_variance], before))
      and same(again, held) and not np.shares_memory(again, held)
      and held.flags.writeable and held.flags.c_contiguous,
      "results keep their values while later runs reuse freed blocks; each run gives its own array")
held[0, 0, 0] = -1.0
check(again[0, 0, 0] != -1.0, "a result is writable, and writing it changes no other result")

# Deprecated forms.
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    sky, distance = volumetricao.occlusion_sweeping(int16, 50, spacing=(1.0, 0.5, 2.0), origin=(1.0, 2.0, 3.0))
check([w.category for w in caught] == [DeprecationWarning, DeprecationWarning]
      and same(distance, volumetricao.occlusion_sweeping(int16, 50, sampling=(2.0, 0.5, 1.0))[1]),
      "spacing (x, y, z) and origin: DeprecationWarning each, spacing read reversed as sampling")
try:
    volumetricao.ambient_occlusion(int16, spacing=(1, 1, 1), sampling=(1, 1, 1))
    check(False, "spacing and sampling together raise TypeError")
except TypeError:
    check(True, "spacing and sampling together raise TypeError")

finish("all Python API checks passed")
