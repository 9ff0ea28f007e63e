"""README.md's code blocks, extracted verbatim and run as a reader of the README would,
each in a fresh folder that holds `Data/` and `build/` as the repository root does:

- the pvpython block with pvpython, and with `mpiexec -np 2 pvbatch`: both exit 0 with no
  error logged, and write the same AO (the image's arrays exactly, the surface's AO per
  point);
- every numpy block with Debian's python3 and the package of the build tree;
- the C++ project (the blocks whose first line names a file under app/) with the sh block
  that builds and runs it, against the build tree and against an install.

Usage: pvpython test_readme.py ROOT BUILD_DIR PVPYTHON PVBATCH MPIEXEC SITE_PACKAGES OUT_DIR"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish  # noqa: E402

root, build, pvpython, pvbatch, mpiexec, site_packages, out_dir = sys.argv[1:8]
readme = open(os.path.join(root, "README.md")).read()
blocks = re.findall(r"```(\w+)\n(.*?)```", readme, re.S)
# Children get a clean MPI environment: a singleton's variables would confuse mpiexec.
ENV = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}


def folder(name, build_tree):
    """A fresh folder laid out like the repository root: Data/, and build/ when given."""
    path = os.path.join(out_dir, "readme", name)
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)
    os.symlink(os.path.join(root, "Data"), os.path.join(path, "Data"))
    if build_tree:
        os.symlink(build_tree, os.path.join(path, "build"))
    return path


def run(command, cwd, what, env=ENV, shell=False):
    result = subprocess.run(command, cwd=cwd, env=env, shell=shell, timeout=900, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, universal_newlines=True)
    log = result.stdout
    print(log, flush=True)
    clean = not re.search(r" ERR\| |Traceback|^ERROR:|Segmentation", log, re.M)
    check(result.returncode == 0 and clean, "%s: exit %d%s" % (what, result.returncode, "" if clean else ", errors logged"))
    return result.returncode == 0 and clean


def read(path):
    from vtkmodules.vtkIOXML import vtkXMLPImageDataReader, vtkXMLPPolyDataReader
    reader = vtkXMLPImageDataReader() if path.endswith(".pvti") else vtkXMLPPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def per_point(surface, name):
    """{point rounded to 1e-4: value}: a surface's array whatever its points' order."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    points = vtk_to_numpy(surface.GetPoints().GetData())
    values = vtk_to_numpy(surface.GetPointData().GetArray(name))
    return {tuple(round(float(c), 4) for c in p): float(v) for p, v in zip(points, values)}


# The pvpython script, serially and on 2 ranks.
scripts = [body for lang, body in blocks if lang == "python" and "paraview.simple" in body]
check(len(scripts) == 1, "README.md has one pvpython block", stop=True)
runs = {}
for ranks in (1, 2):
    cwd = folder("pvpython_np%d" % ranks, build)
    with open(os.path.join(cwd, "script.py"), "w") as f:
        f.write(scripts[0])
    command = [pvpython, "script.py"] if ranks == 1 else \
        [mpiexec, "--allow-run-as-root", "--oversubscribe", "-np", str(ranks), pvbatch, "script.py"]
    if run(command, cwd, "the pvpython block on %d rank(s)" % ranks):
        runs[ranks] = cwd
written = sorted(set(re.findall(r'SaveData\("([^"]+)"', scripts[0])))
check(bool(written), "the pvpython block writes files (%s)" % written)
if len(runs) == 2:
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    for name in written:
        serial, distributed = (read(os.path.join(runs[r], name)) for r in (1, 2))
        if name.endswith(".pvti"):
            pd = serial.GetPointData()
            for i in range(pd.GetNumberOfArrays()):
                array = pd.GetArrayName(i)
                other = distributed.GetPointData().GetArray(array)
                same = other is not None and np.array_equal(vtk_to_numpy(pd.GetArray(i)), vtk_to_numpy(other))
                check(same, "%s: %s on 2 ranks equals serial" % (name, array))
        else:
            a, b = per_point(serial, "AmbientOcclusion"), per_point(distributed, "AmbientOcclusion")
            worst = max(abs(a[p] - b[p]) for p in a) if set(a) == set(b) and a else float("inf")
            check(worst <= 1e-6, "%s: AmbientOcclusion at %d points on 2 ranks equals serial (max |diff| %g)"
                  % (name, len(a), worst))

# The numpy blocks, in Debian's python3 with the build tree's package.
env = dict(ENV, PYTHONPATH=site_packages)
for n, body in enumerate(body for lang, body in blocks if lang == "python" and "paraview.simple" not in body):
    cwd = folder("numpy_%d" % n, None)
    with open(os.path.join(cwd, "block.py"), "w") as f:
        f.write(body)
    run(["/usr/bin/python3", "block.py"], cwd, "numpy block %d" % n, env=env)

# The C++ project, built and run by the sh block that follows it, against the build tree
# and against an install.
files = {}
for lang, body in blocks:
    named = re.match(r"(?:#|//) (app/[\w.]+)", body)
    if named and lang in ("cmake", "cpp"):
        files[named.group(1)] = body
check(sorted(files) == ["app/CMakeLists.txt", "app/main.cxx"], "README.md's C++ project: %s" % sorted(files),
      stop=True)
commands = [body for lang, body in blocks if lang == "sh" and "cmake -S app" in body]
check(len(commands) == 1, "README.md has the C++ project's build commands", stop=True)
install = os.path.join(out_dir, "readme", "install")
shutil.rmtree(install, ignore_errors=True)
run(["cmake", "--install", build, "--prefix", install], out_dir, "cmake --install the build tree")
for tree, prefix in (("build tree", build), ("install", install)):
    cwd = folder("cxx_" + tree.replace(" ", "_"), prefix)
    for name, body in files.items():
        os.makedirs(os.path.join(cwd, os.path.dirname(name)), exist_ok=True)
        with open(os.path.join(cwd, name), "w") as f:
            f.write(body)
    if run(["bash", "-euo", "pipefail", "-c", commands[0]], cwd, "the C++ project against the " + tree):
        from vtkmodules.vtkIOXML import vtkXMLImageDataReader
        read_vti = vtkXMLImageDataReader()
        read_vti.SetFileName(os.path.join(cwd, "ct_ao.vti"))
        read_vti.Update()
        image = read_vti.GetOutput()
        array = image.GetPointData().GetArray("AmbientOcclusion")
        check(array is not None and array.GetNumberOfTuples() == image.GetNumberOfPoints() > 0
              and 0.0 <= array.GetRange()[0] < array.GetRange()[1] <= 1.0,
              "the C++ project against the %s wrote AmbientOcclusion in [0, 1]" % tree)
finish("README.md's blocks run as written")
