"""Checks that the filter reference pages in docs/filters match the ParaView proxies.

Usage: python3 Testing/Python/test_docs.py REPO_ROOT

Standard library only. For every SourceProxy of Plugin/*.xml it finds the proxy's page
(PAGES below) and checks that every property of the proxy is a row of the page's
properties table (a table whose header starts with "| Property |"), written as
`PropertyName` in backticks in the first cell, and that the table documents no property
the proxy does not have (a renamed or removed one). It also checks that the images the
pages show exist, and that no file of the repository refers to the reference text outside
it (the string built in OUTSIDE_REFERENCE), and that every relative link of README.md,
Data/README.md, CUDA/README.md and docs/ names a file that exists, as does every
repository path they name in their text (CUDA/..., Testing/..., and so on). It prints "ok: ..." or
"FAILED: ..." per check (vao_test_utils.check) and ends with "N passed, M failed"; the exit
status is 1 when anything failed.
"""
import glob
import os
import re
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish, summary  # noqa: E402

# Proxy name (the SourceProxy's name attribute) -> its page, relative to the repository.
PAGES = {
    "VolumetricAmbientOcclusion": "docs/filters/volumetric-ambient-occlusion.md",
    "OcclusionSweeping": "docs/filters/occlusion-sweeping.md",
    "VarianceOcclusionMap": "docs/filters/variance-occlusion-map.md",
    "IsosurfaceAmbientOcclusion": "docs/filters/isosurface-ambient-occlusion.md",
    "AmbientOcclusionShading": "docs/filters/ambient-occlusion-shading.md",
    "AmbientOcclusionHeadPhantom": "docs/filters/head-phantom.md",
    "ProbeOutsideSurface": "docs/filters/probe-outside-surface.md",
}

# The repository must stand alone: no reference to the text beside the checkout. Built
# from two parts so that this file does not match itself.
OUTSIDE_REFERENCE = "shared/" + "METHODS.md"
SEARCHED = ["README.md", "docs", "Filters", "CUDA", "Plugin", "Python", "Testing", "Examples",
            "Benchmarks", "cmake", ".ci"]
SKIPPED_DIRECTORIES = {".git", "__pycache__"}

# Elements under a SourceProxy whose Property children are references, not properties.
REFERENCE_CONTAINERS = {"PropertyGroup", "Hints", "RequiredProperties", "ExposedProperties"}

TABLE_ROW = re.compile(r"^\s*\|(.*)\|\s*$")
PROPERTY_CELL = re.compile(r"^`([A-Za-z_][A-Za-z0-9_]*)`$")
IMAGE_LINK = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")


def proxy_properties(proxy):
    """The names of the proxy's properties, in the XML's order (references excluded)."""
    names = []

    def walk(element):
        for child in element:
            tag = child.tag if isinstance(child.tag, str) else ""
            if tag in REFERENCE_CONTAINERS:
                continue
            name = child.get("name")
            if tag.endswith("Property") and tag != "Property" and name:
                names.append(name)
            walk(child)

    walk(proxy)
    return names


def source_proxies(plugin_dir):
    """(proxy name, xml file, property names) for every SourceProxy of Plugin/*.xml."""
    proxies = []
    files = sorted(f for f in os.listdir(plugin_dir) if f.endswith(".xml")) if os.path.isdir(plugin_dir) else []
    check(bool(files), "Plugin/*.xml found under %s" % plugin_dir)
    # The properties the proxies share stand where a proxy says @NAME@ (Plugin/CMakeLists.txt
    # puts them there): Plugin/NumberOfThreads.xml.
    shared = {}
    for name in files:
        if "<SourceProxy" not in open(os.path.join(plugin_dir, name), encoding="utf-8").read():
            shared["@VAO_%s_PROPERTY@" % re.sub(r"(?<!^)(?=[A-Z])", "_", name[:-4]).upper()] = \
                open(os.path.join(plugin_dir, name), encoding="utf-8").read()
    for name in files:
        path = os.path.join(plugin_dir, name)
        text = open(path, encoding="utf-8").read()
        if "<SourceProxy" not in text:
            continue
        for placeholder, fragment in shared.items():
            text = text.replace(placeholder, fragment)
        try:
            root = ET.fromstring(text)
        except ET.ParseError as error:
            check(False, "Plugin/%s does not parse: %s" % (name, error))
            continue
        for proxy in root.iter("SourceProxy"):
            proxies.append((proxy.get("name"), name, proxy_properties(proxy)))
    return proxies


def documented_properties(text):
    """{name: line number} of the first cells of the page's properties tables."""
    rows = {}
    in_table = False
    header_next = False
    for number, line in enumerate(text.splitlines(), start=1):
        match = TABLE_ROW.match(line)
        if not match:
            in_table = header_next = False
            continue
        cells = [c.strip() for c in match.group(1).split("|")]
        if header_next:  # the |---|---| line under the header
            header_next = False
            continue
        if not in_table and cells and cells[0] == "Property":
            in_table = header_next = True
            continue
        if in_table:
            cell = PROPERTY_CELL.match(cells[0]) if cells else None
            if cell:
                rows.setdefault(cell.group(1), number)
    return rows


def check_pages(root):
    for proxy, xml_file, properties in source_proxies(os.path.join(root, "Plugin")):
        page = PAGES.get(proxy)
        if not check(page is not None,
                     "proxy %s (Plugin/%s) has a page in docs/filters (PAGES names it)" % (proxy, xml_file)):
            continue
        path = os.path.join(root, page)
        if not check(os.path.isfile(path), "proxy %s: its page %s exists" % (proxy, page)):
            continue
        with open(path, encoding="utf-8") as f:
            text = f.read()
        rows = documented_properties(text)
        if not check(bool(rows), "%s: a properties table (a header '| Property | Default | ...')" % page):
            continue
        for name in properties:
            check(name in rows, "%s: property `%s` of proxy %s (Plugin/%s) is a row of the properties table"
                  % (page, name, proxy, xml_file))
        known = set(properties)
        for name, line in sorted(rows.items(), key=lambda item: item[1]):
            check(name in known, "%s:%d: documents `%s`, a property of proxy %s (Plugin/%s) (not renamed or "
                  "removed)" % (page, line, name, proxy, xml_file))
        for line_number, line in enumerate(text.splitlines(), start=1):
            for target in IMAGE_LINK.findall(line):
                if "://" in target:
                    continue
                image = os.path.normpath(os.path.join(os.path.dirname(path), target))
                check(os.path.isfile(image), "%s:%d: image %s exists" % (page, line_number, target))


def searched_files(root):
    for entry in SEARCHED:
        path = os.path.join(root, entry)
        if os.path.isfile(path):
            yield path
        elif os.path.isdir(path):
            for directory, subdirectories, files in os.walk(path):
                subdirectories[:] = sorted(d for d in subdirectories if d not in SKIPPED_DIRECTORIES)
                for name in sorted(files):
                    yield os.path.join(directory, name)


def check_outside_references(root):
    needle = OUTSIDE_REFERENCE.encode()
    found = False
    for path in searched_files(root):
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            continue
        start = data.find(needle)
        while start >= 0:
            found = True
            line = data.count(b"\n", 0, start) + 1
            check(False, "%s:%d: refers to %s, outside the repository" %
                  (os.path.relpath(path, root), line, OUTSIDE_REFERENCE))
            start = data.find(needle, start + len(needle))
    if not found:
        check(True, "no file refers to %s" % OUTSIDE_REFERENCE)


def check_links(root):
    """Every relative link of the README and the manual names a file of the repository."""
    pages = [os.path.join(root, "README.md"), os.path.join(root, "Data", "README.md"),
             os.path.join(root, "CUDA", "README.md")]
    for folder, _, files in os.walk(os.path.join(root, "docs")):
        pages += [os.path.join(folder, f) for f in sorted(files) if f.endswith(".md")]
    for page in pages:
        if not os.path.exists(page):
            continue
        text = open(page, encoding="utf-8").read()
        for match in re.finditer(r"\]\(([^)#\s]+)(#[^)]*)?\)", text):
            target = match.group(1)
            if "://" in target or target.startswith("mailto:"):
                continue
            resolved = os.path.normpath(os.path.join(os.path.dirname(page), target))
            line = text.count("\n", 0, match.start()) + 1
            check(os.path.exists(resolved), "%s:%d: link to %s, which exists"
                  % (os.path.relpath(page, root), line, target))


# A repository path in the text: a top-level folder of the repository, then a path, after
# a space, a backtick, a bracket or a parenthesis (so that build/Testing/... is not one).
TOP_LEVEL = ("CUDA", "Filters", "Plugin", "Python", "Testing", "Examples", "Benchmarks", "Data", "docs",
             "cmake", ".ci")
NAMED_PATH = re.compile(r"(?:^|(?<=[\s`(\[\"']))((?:%s)/[A-Za-z0-9_.*/+-]*)" % "|".join(re.escape(t) for t in TOP_LEVEL),
                        re.M)

SOURCE_NAME = re.compile(r"`([A-Za-z0-9_-]+\.(?:cxx|h|cu|py|xml|cmake|sh))`")


def manual_pages(root):
    pages = [os.path.join(root, "README.md"), os.path.join(root, "Data", "README.md"),
             os.path.join(root, "CUDA", "README.md")]
    for folder, _, files in os.walk(os.path.join(root, "docs")):
        pages += [os.path.join(folder, f) for f in sorted(files) if f.endswith(".md")]
    return [page for page in pages if os.path.exists(page)]


def check_named_paths(root):
    """Every repository path the README and the manual name (in text, code or commands)
    exists: a file or folder, or a pattern with * that matches one."""
    count = 0
    for page in manual_pages(root):
        text = open(page, encoding="utf-8").read()
        for match in NAMED_PATH.finditer(text):
            path = match.group(1).rstrip(".,:;")
            count += 1
            line = text.count("\n", 0, match.start()) + 1
            where = os.path.join(root, path)
            exists = bool(glob.glob(where)) if "*" in path else os.path.exists(where)
            if not exists:
                check(False, "%s:%d: names %s, which does not exist" % (os.path.relpath(page, root), line, path))
    check(count > 100, "%d repository paths named in README.md and docs/, every one exists (or is listed above)"
          % count)
    # A source file named alone (`vtkFoo.cxx`, `Parallel.h`) is a file of the repository.
    names = set()
    for folder, directories, files in os.walk(root):
        directories[:] = [d for d in directories if d != ".git" and not d.startswith("build")]
        names.update(files)
    for page in manual_pages(root):
        text = open(page, encoding="utf-8").read()
        for match in SOURCE_NAME.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            if match.group(1) not in names:
                check(False, "%s:%d: names %s, which is no file of the repository"
                      % (os.path.relpath(page, root), line, match.group(1)))


def main(argv):
    if len(argv) != 2:
        sys.stderr.write("usage: python3 %s REPO_ROOT\n" % argv[0])
        return 2
    root = os.path.abspath(argv[1])
    check_pages(root)
    check_outside_references(root)
    check_links(root)
    check_named_paths(root)
    print(summary())
    finish("the manual matches the plugin")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
