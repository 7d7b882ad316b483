#!/usr/bin/env python3
"""How fast large glTF files load, and the memory the load takes, against the file's geometry.

Writes three binary glTF files into a scratch folder (nothing is committed or downloaded) and
runs `photonlab bench --load` on each, printing one Markdown table (docs: reference/gltf.md, "Large
files"):
  grid        a 1415 x 1415 height field: 4.0 M triangles, POSITION and uint32 indices only
              (72 MB of geometry: the file of issue 16)
  grid+attrs  the same with NORMAL and TEXCOORD_0 (112 MB)
  instanced   one 100 k-triangle grid placed by 64 nodes: 6.4 M triangles, 100 k stored

    /usr/bin/python3 scripts/load_benchmark.py [--photonlab build/photonlab] [--dir /tmp/x] [--size N]
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np


def grid_arrays(n):
    """A wavy n x n height field over [-1, 1]^2: positions, normals, uvs, counter-clockwise
    triangles seen from +y."""
    xs = np.linspace(-1, 1, n, dtype=np.float32)
    x, z = np.meshgrid(xs, xs)
    y = 0.05 * np.sin(8 * x) * np.cos(8 * z)
    positions = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    # The height field's normal (-dy/dx, 1, -dy/dz), normalised.
    dydx = 0.4 * np.cos(8 * x) * np.cos(8 * z)
    dydz = -0.4 * np.sin(8 * x) * np.sin(8 * z)
    normals = np.stack([-dydx, np.ones_like(x), -dydz], -1).reshape(-1, 3)
    normals = (normals / np.linalg.norm(normals, axis=1, keepdims=True)).astype(np.float32)
    uvs = np.stack([(x + 1) / 2, (z + 1) / 2], -1).reshape(-1, 2).astype(np.float32)
    i = np.arange(n * n, dtype=np.uint32).reshape(n, n)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, :-1], i[1:, 1:]
    triangles = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3),
                                np.stack([b, c, d], -1).reshape(-1, 3)]).astype(np.uint32)
    return positions, normals, uvs, triangles


def write_glb(path, n, attributes=False, placements=1):
    """A .glb with one grid mesh of n x n vertices, placed by `placements` nodes on a square
    lattice (more than one: the loader instances it), a camera and a point light above."""
    positions, normals, uvs, triangles = grid_arrays(n)
    arrays = [positions] + ([normals, uvs] if attributes else []) + [triangles]
    blob, views = bytearray(), []
    for a in arrays:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": a.nbytes})
        blob += a.tobytes()
    accessors = [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
                  "min": positions.min(0).tolist(), "max": positions.max(0).tolist()}]
    attrs = {"POSITION": 0}
    if attributes:
        accessors += [{"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5126, "count": len(uvs), "type": "VEC2"}]
        attrs.update({"NORMAL": 1, "TEXCOORD_0": 2})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": int(triangles.size),
                      "type": "SCALAR"})
    side = int(np.ceil(np.sqrt(placements)))
    nodes = [{"mesh": 0, "translation": [2.2 * (k % side), 0, 2.2 * (k // side)]} for k in range(placements)]
    centre = 1.1 * (side - 1)
    nodes += [{"camera": 0, "translation": [centre, 1.5 * side, centre + 2.5 * side],
               "rotation": [-0.2588, 0, 0, 0.9659]},
              {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [centre, 2.0 * side, centre]}]
    doc = {"asset": {"version": "2.0", "generator": "photonlab scripts/load_benchmark.py",
                     "extras": {"photonlab": {"units": "radiometric"}}},
           "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
           "extensionsUsed": ["KHR_lights_punctual"],
           "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0 * side * side}]}},
           "meshes": [{"primitives": [{"attributes": attrs, "indices": len(accessors) - 1}]}],
           "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(blob)}]}
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    tmp = path + ".part"
    with open(tmp, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(blob)))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<II", len(blob), 0x004E4942) + bytes(blob))
    os.replace(tmp, path)
    return len(triangles) * placements


def bench(photonlab, path, repeats):
    """photonlab bench --load's table as {measure: value}."""
    out = subprocess.run([photonlab, "bench", "--load", path, "--repeats", str(repeats)], check=True,
                         capture_output=True, text=True).stdout
    rows = {}
    for line in out.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 2 and cells[0] not in ("measure", "---"):
            rows[cells[0]] = cells[1]
    return rows


def main(argv=None):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--photonlab", default=os.path.join(root, "build", "photonlab"))
    p.add_argument("--dir", help="where the files go (default: a temporary folder, removed after)")
    p.add_argument("--size", type=int, default=1415, help="grid vertices a side (1415: 4.0 M triangles)")
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as scratch:
        folder = args.dir or scratch
        os.makedirs(folder, exist_ok=True)
        cases = [("grid", dict(n=args.size)), ("grid+attrs", dict(n=args.size, attributes=True)),
                 ("instanced", dict(n=max(2, round(args.size / 6.3)), placements=64))]
        print("| file | triangles (stored) | geometry (MB) | BVH | load (s) | M triangles/s | peak memory (MB) | peak / geometry |")
        print("|---|---|---|---|---|---|---|---|")
        for name, kw in cases:
            path = os.path.join(folder, name + ".glb")
            write_glb(path, **kw)
            r = bench(args.photonlab, path, args.repeats)
            print("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
                name, r["triangles (stored)"], r["geometry in the file (MB)"], r["BVH"],
                r["load, until the scene can be traced (s)"], r["load rate (M triangles/s)"],
                r["peak memory of the load (MB)"], r["peak memory / geometry"]))
            sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
