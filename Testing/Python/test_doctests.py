"""The examples of the Python package's documentation run: the doctests of every module of
volumetricao, and the ```python blocks of docs/python.md, in order, in one namespace, from
the repository's root (```py blocks, which need packages the tests do not have, are only
shown).
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_doctests.py SITE_PACKAGES_DIR REPOSITORY_ROOT"""
import doctest
import inspect
import os
import re
import sys
import traceback
import warnings

site, root = sys.argv[1], os.path.abspath(sys.argv[2])
sys.path.insert(0, site)
import volumetricao  # noqa: E402
from volumetricao import _common, numpy_helpers, surfaces, volumes  # noqa: E402

from vao_test_utils import check, finish  # noqa: E402


# pvpython's sys.stdout has no encoding, which doctest reads: print to the process's own.
if not hasattr(sys.stdout, "encoding") and sys.__stdout__ is not None:
    sys.stdout = sys.__stdout__
for module in (volumetricao, volumes, surfaces, _common, numpy_helpers):
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    check(result.failed == 0, "%s: %d doctests, %d failed" % (module.__name__, result.attempted, result.failed))
documented = [getattr(volumetricao, name) for name in volumetricao.__all__ if not name.startswith("vtk")]
check(all((item.__doc__ or "").strip() for item in documented), "every public name has a docstring")
functions = [f for f in documented if inspect.isfunction(f)]
check(len(functions) == 5 and all(">>> " in f.__doc__ for f in functions),
      "the five numpy functions have examples: %s" % [f.__name__ for f in functions])

os.chdir(root)
page = open(os.path.join(root, "docs", "python.md")).read()
blocks = re.findall(r"^```python\n(.*?)^```", page, re.M | re.S)
namespace = {"__name__": "__docs__"}
for number, block in enumerate(blocks, 1):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", DeprecationWarning)
            exec(compile(block, "docs/python.md block %d" % number, "exec"), namespace)
        check(True, "docs/python.md block %d of %d runs (%s...)" % (number, len(blocks), block.strip()[:40]))
    except Exception:  # noqa: BLE001
        check(False, "docs/python.md block %d runs:\n%s" % (number, traceback.format_exc()))
check(len(blocks) >= 8, "docs/python.md has its examples (%d python blocks)" % len(blocks))
finish("all documentation examples ran")
