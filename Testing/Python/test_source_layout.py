"""Checks the layout rules of docs/development.md ("Where code lives") on the source tree.

Usage: python3 Testing/Python/test_source_layout.py REPO_ROOT

Standard library only, no build needed. The rules:
- the public headers (CUDA/include) are the interface: no `namespace detail` in them, and no
  CMakeLists.txt outside CUDA/ puts the kernel's sources (CUDA/src) on an include path;
- a method folder of the kernel (CUDA/src/cpu/<method>, CUDA/src/cuda/<method>) includes
  only itself, the shared folders (common/, simd/) and the public headers: what two
  methods share lives in a shared folder;
- no include circles: no file reaches itself through its includes, a class whose member
  functions are defined in several files counting as one;
- every class of Filters/ and Plugin/ defines its member functions in one .cxx.
It prints "ok: ..." or "FAILED: ..." per check and ends with "N passed, M failed".
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish, summary  # noqa: E402

SOURCES = (".h", ".cxx", ".cu", ".cuh")
TREES = ["CUDA", "Filters", "Plugin", "Testing", "Benchmarks", "Examples"]
# Where a quoted include is looked for after the including file's folder.
INCLUDE_ROOTS = ["CUDA/include", "CUDA/src", "CUDA/tests", "Filters", "Plugin", "Testing/Cxx", "Benchmarks"]
# The kernel's folders every method may include (and the dispatchers at the top).
SHARED_FOLDERS = {"common", "simd"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
MEMBER_DEFINITION = re.compile(r"^[A-Za-z_][\w:<>,\s\*&]*?\b(vtk\w+|pq\w+)::~?\w+\s*\(", re.M)


def source_files(root):
    for tree in TREES:
        for folder, directories, files in os.walk(os.path.join(root, tree)):
            directories[:] = [d for d in directories if d not in {"__pycache__", ".git"}]
            for name in files:
                if name.endswith(SOURCES):
                    yield os.path.relpath(os.path.join(folder, name), root)


def read(root, path):
    with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
        return f.read()


def resolve(root, including, name):
    for base in [os.path.dirname(including)] + INCLUDE_ROOTS:
        candidate = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(os.path.join(root, candidate)):
            return candidate
    return None


def check_public_headers(root):
    leaks = []
    for folder, _, files in os.walk(os.path.join(root, "CUDA", "include")):
        for name in files:
            path = os.path.relpath(os.path.join(folder, name), root)
            for number, line in enumerate(read(root, path).splitlines(), 1):
                if re.search(r"\bnamespace\s+detail\b", line):
                    leaks.append("%s:%d" % (path, number))
    check(not leaks, "no namespace detail in the public headers%s" % (": " + ", ".join(leaks) if leaks else ""))
    reaching = []
    for folder, directories, files in os.walk(root):
        directories[:] = [d for d in directories if not d.startswith((".", "build"))]
        relative = os.path.relpath(folder, root)
        if relative == "CUDA" or relative.startswith("CUDA" + os.sep):
            continue
        if "CMakeLists.txt" in files:
            path = os.path.join(relative, "CMakeLists.txt")
            for number, line in enumerate(read(root, path).splitlines(), 1):
                if "CUDA/src" in line:
                    reaching.append("%s:%d" % (os.path.normpath(path), number))
    check(not reaching, "no CMakeLists.txt outside the kernel names CUDA/src%s"
          % (": " + ", ".join(reaching) if reaching else ""))


def method_folder(path):
    """('cpu', 'box_statistics') for a file of a method folder of the kernel, else None."""
    parts = path.split("/")
    if len(parts) >= 5 and parts[:2] == ["CUDA", "src"] and parts[2] in ("cpu", "cuda"):
        return parts[2], parts[3]
    return None


def check_method_folders(root, includes):
    reaches = []
    for path, targets in sorted(includes.items()):
        own = method_folder(path)
        if own is None or own[1] in SHARED_FOLDERS:
            continue
        for target in targets:
            other = method_folder(target)
            if other is not None and other[1] != own[1] and other[1] not in SHARED_FOLDERS:
                reaches.append("%s -> %s" % (path, target))
    check(not reaches, "every method folder stands alone (includes only itself, common/, simd/)%s"
          % (": " + "; ".join(reaches) if reaches else ""))
    shared = []
    for path, targets in sorted(includes.items()):
        own = method_folder(path)
        if own is None or own[1] not in SHARED_FOLDERS:
            continue
        for target in targets:
            other = method_folder(target)
            if other is not None and other[1] not in SHARED_FOLDERS:
                shared.append("%s -> %s" % (path, target))
    check(not shared, "the shared folders include no method folder%s" % (": " + "; ".join(shared) if shared else ""))


def classes_by_file(root, paths):
    """{file: the classes whose member functions it defines} for the VTK and Qt layers."""
    defined = {}
    for path in paths:
        if path.endswith(".cxx") and path.split("/")[0] in ("Filters", "Plugin"):
            defined[path] = set(MEMBER_DEFINITION.findall(read(root, path)))
    return defined


def check_one_file_per_class(defined):
    files_of = {}
    for path, classes in defined.items():
        for name in classes:
            files_of.setdefault(name, set()).add(path)
    split = {name: sorted(files) for name, files in files_of.items() if len(files) > 1}
    check(not split, "every class defines its member functions in one .cxx%s"
          % (": " + "; ".join("%s in %s" % (n, ", ".join(f)) for n, f in sorted(split.items())) if split else ""))
    return files_of


def check_circles(includes, files_of):
    # A node per file, except that the files of one class (its header and every .cxx that
    # defines its members) are one node.
    node = {}
    for name, files in files_of.items():
        header = None
        for path in files:
            candidate = os.path.join(os.path.dirname(path), name + ".h")
            if candidate in includes:
                header = candidate
        for path in list(files) + ([header] if header else []):
            node[path] = "class " + name
    graph = {}
    for path, targets in includes.items():
        edges = graph.setdefault(node.get(path, path), set())
        for target in targets:
            if node.get(target, target) != node.get(path, path):
                edges.add(node.get(target, target))
    circles = []
    state = {}

    def visit(start):
        stack = [(start, iter(sorted(graph.get(start, ()))))]
        trail = [start]
        state[start] = 1
        while stack:
            current, edges = stack[-1]
            following = next(edges, None)
            if following is None:
                state[current] = 2
                stack.pop()
                trail.pop()
                continue
            if state.get(following) == 1:
                circles.append(" -> ".join(trail[trail.index(following):] + [following]))
            elif following not in state:
                state[following] = 1
                stack.append((following, iter(sorted(graph.get(following, ())))))
                trail.append(following)

    for start in sorted(graph):
        if start not in state:
            visit(start)
    check(not circles, "no include circles%s" % (": " + "; ".join(circles) if circles else ""))


def main(argv):
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    paths = sorted(source_files(root))
    includes = {}
    for path in paths:
        targets = [resolve(root, path, name) for name in INCLUDE.findall(read(root, path))]
        includes[path] = sorted({t for t in targets if t})
    check(len(paths) > 100, "%d source files read" % len(paths), stop=True)
    check_public_headers(root)
    check_method_folders(root, includes)
    files_of = check_one_file_per_class(classes_by_file(root, paths))
    check_circles(includes, files_of)
    finish(summary())


if __name__ == "__main__":
    main(sys.argv)
