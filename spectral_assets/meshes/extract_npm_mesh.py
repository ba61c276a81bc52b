#!/usr/bin/env python3
"""Convert a mesh from an npm package of the `positions` / `cells` kind
(mikolalysenko's `teapot` and `bunny`) to a Wavefront OBJ file.

The package's JavaScript module holds `positions` (vertex coordinates) and
`cells` (triangles as 0-based vertex indices) as array literals; this reads
them as JSON and writes `v` and `f` lines (1-based), with fixed formatting so
the output is reproducible. Python 3 standard library only.

    tmp=$(mktemp -d)
    (cd "$tmp" && npm pack teapot@1.0.0 && tar xzf teapot-1.0.0.tgz)
    python3 spectral_assets/meshes/extract_npm_mesh.py "$tmp/package/teapot.js" \\
        spectral_assets/meshes/teapot.obj --source "npm teapot@1.0.0"
"""

import argparse
import json
import re


def read_arrays(js_text):
    """The `positions` and `cells` array literals of the module."""
    out = {}
    for name in ("positions", "cells"):
        m = re.search(r"\b" + name + r"\s*[=:]\s*(\[\s*\[.*?\]\s*\])", js_text, re.S)
        if not m:
            raise SystemExit(f"no `{name}` array found")
        out[name] = json.loads(m.group(1))
    return out["positions"], out["cells"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("module", help="the package's .js file")
    ap.add_argument("out", help="OBJ file to write")
    ap.add_argument("--source", required=True, help="where the mesh came from, for the header")
    a = ap.parse_args()
    with open(a.module) as f:
        positions, cells = read_arrays(f.read())
    n = len(positions)
    for c in cells:
        if len(c) != 3 or not all(0 <= i < n for i in c):
            raise SystemExit(f"bad triangle {c}")
    with open(a.out, "w", newline="\n") as f:
        f.write(f"# {a.source}: {n} vertices, {len(cells)} triangles\n")
        for p in positions:
            f.write("v {:.6f} {:.6f} {:.6f}\n".format(*p))
        for c in cells:
            f.write("f {} {} {}\n".format(*(i + 1 for i in c)))
    print(f"wrote {a.out}: {n} vertices, {len(cells)} triangles")


if __name__ == "__main__":
    main()
