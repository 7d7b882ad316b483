#!/usr/bin/python3
"""The folders of src/ are layers: a folder may include its own headers and those of the folders
below it, never one above. This script computes the folder include graph from every
`#include "folder/file.h"` under src/, fails (exit 1) on any cycle and on any include that climbs
the order below, naming the file and the line, and prints the order with each folder's uses.

    python3 scripts/check_layers.py            # the order and what each folder includes
    python3 scripts/check_layers.py --quiet    # only the violations

A new folder is added to LAYERS at the height of what it needs; tests/test_scripts.py runs this."""
import argparse
import os
import re
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# Bottom first. Each line may include the folders on its own line's left and on the lines above.
LAYERS = [
    "core",         # types, random numbers, sampling warps, the parallel loop, budgets, exact sums
    "optics",       # reflection, refraction, Fresnel
    "spectral",     # CIE tables, XYZ and sRGB, the RGB uplift, sampled wavelengths
    "image",        # images, textures, tone curves: what lights and BSDFs read from below
    "bsdfs",        # the BSDF interface and one file per BSDF
    "lights",       # the light interface and one file per light
    "scene",        # geometry (Embree), materials, camera, the glTF loader
    "transport",    # the light subpath's walk, shared by light tracing, bidirectional and photons
    "photon",       # photon records, photon maps, the photon tracer
    "guiding",      # path guiding's distributions
    "radiosity",    # patches, form factors, the radiosity solver
    "render",       # the integrator interface, films, the render loops, the visibility probe
    "integrators",  # one file per integrator, their parameters and the registry
    "io",           # image files, error metrics
    "experiment",   # experiment configs and the runner
    "bench",        # the bench's yardsticks
    "cli",          # the photonlab command
]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/[^"]+"', re.M)


def graph(src):
    """{folder: {included folder: [(file, line), ...]}} over every source file under src."""
    edges = {}
    for folder, _, names in os.walk(src):
        for name in sorted(names):
            if not name.endswith((".h", ".cpp", ".hpp", ".cc")):
                continue
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, src)
            here = rel.split(os.sep)[0]
            text = open(path, encoding="utf-8").read()
            for m in INCLUDE.finditer(text):
                there = m.group(1)
                if there != here:
                    line = text.count("\n", 0, m.start()) + 1
                    edges.setdefault(here, {}).setdefault(there, []).append((rel, line))
    return edges


def cycles(edges):
    """Every strongly connected component of more than one folder (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(set(edges) | {w for e in edges.values() for w in e}):
        if v not in index:
            visit(v)
    return out


def check(src):
    """(violations as lines, the printed order)."""
    edges = graph(src)
    problems = []
    folders = sorted({f for f in os.listdir(src) if os.path.isdir(os.path.join(src, f))})
    for f in folders:
        if f not in LAYERS:
            problems.append(f"src/{f}/: a folder that is in no layer (add it to LAYERS in scripts/check_layers.py)")
    for comp in cycles(edges):
        problems.append("cycle between the folders " + ", ".join(comp))
    rank = {f: i for i, f in enumerate(LAYERS)}
    for here, uses in sorted(edges.items()):
        for there, where in sorted(uses.items()):
            if here in rank and there in rank and rank[there] > rank[here]:
                for rel, line in where:
                    problems.append(f"src/{rel}:{line}: {here}/ includes {there}/, a layer above it")
    order = []
    for f in LAYERS:
        uses = ", ".join(sorted(edges.get(f, {}))) or "nothing else"
        order.append(f"{rank[f] + 1:2d}. {f:<12} uses {uses}")
    return problems, order


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--src", default=os.path.join(ROOT, "src"))
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args(argv)
    problems, order = check(a.src)
    if not a.quiet:
        print("src/ layers, bottom first:")
        print("\n".join(order))
    for line in problems:
        print(f"check_layers: {line}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
