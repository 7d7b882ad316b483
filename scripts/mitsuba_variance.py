#!/usr/bin/env python3
"""Per-sample variance of photonlab's path tracer against Mitsuba 3's, path length by path length.

Both renderers trace the same scene (a photonlab glTF written by make_scenes.py, converted here to
PLY meshes and a Mitsuba scene dictionary), at the same resolution, box filter, independent
sampling, next-event estimation with BSDF-sampling MIS. For each maximum path length d (segments
after the camera ray: photonlab --max-depth d, Mitsuba max_depth d + 1) it renders K independent
images of S samples per pixel and reports, over all pixels and over the ceiling's pixels:

  mean        the mean over those pixels (the two must agree: same scene, same answer)
  var/sample  S times the variance of a pixel's S-sample estimate over the K images, averaged
              over the pixels (the per-sample variance that equal-time error is made of)

Pixels that see an emitter are left out (their coverage variance is the same in both and would
dominate); "indirect" is the pixels that depth 1 leaves black, such as the Cornell ceiling.
A pixel's variance estimate from K images has a relative error of √(2/(K − 1)): K = 64 gives
18% per pixel, ~1–3% over the hundreds of pixels averaged.

Their ratio by d shows where an excess of variance begins. Needs Mitsuba 3 in the interpreter
that runs this (pip install mitsuba in a virtual environment) and, for its llvm_ad_rgb variant,
DRJIT_LIBLLVM_PATH pointing at a libLLVM ≥ 16 (Debian 12: apt install libllvm19).

  DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so venv/bin/python \\
      scripts/mitsuba_variance.py scenes/cornell-spheres.gltf --photonlab build/photonlab
"""
import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np


def read_gltf(path):
    """Meshes (world positions, normals or None, indices, material index), materials, camera."""
    doc = json.load(open(path))
    blobs = []
    for b in doc["buffers"]:
        uri = b["uri"]
        if uri.startswith("data:"):
            blobs.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            blobs.append(open(os.path.join(os.path.dirname(path), uri), "rb").read())

    def accessor(i):
        a = doc["accessors"][i]
        v = doc["bufferViews"][a["bufferView"]]
        n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
        dtype = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a["componentType"]]
        off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        data = np.frombuffer(blobs[v["buffer"]], dtype=dtype, count=a["count"] * n, offset=off)
        return data.reshape(a["count"], n) if n > 1 else data

    meshes, camera = [], None
    for node in doc["nodes"]:
        if any(k in node for k in ("matrix", "scale")) or ("mesh" in node and ("rotation" in node or "translation" in node)):
            sys.exit(f"{path}: node '{node.get('name')}' has a transform; only make_scenes.py's flat layout is converted")
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                attrs = prim["attributes"]
                meshes.append((accessor(attrs["POSITION"]), accessor(attrs["NORMAL"]) if "NORMAL" in attrs else None,
                               accessor(prim["indices"]).reshape(-1, 3), prim["material"]))
        if "camera" in node:
            x, y, z, w = node["rotation"]
            # Rotated -Z (forward) and +Y (up) of the glTF camera.
            forward = [-(2 * (x * z + w * y)), -(2 * (y * z - w * x)), -(1 - 2 * (x * x + y * y))]
            up = [2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)]
            camera = (node["translation"], forward, up, doc["cameras"][node["camera"]]["perspective"]["yfov"])
    return meshes, doc["materials"], camera


def mitsuba_bsdf(m):
    pbr = m.get("pbrMetallicRoughness", {})
    base = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
    ext = m.get("extensions", {})
    if "KHR_materials_transmission" in ext:
        ior = ext.get("KHR_materials_ior", {}).get("ior", 1.5)
        return {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0}
    if pbr.get("metallicFactor", 1.0) == 1.0 and pbr.get("roughnessFactor", 1.0) == 0.0:
        # photonlab's Mirror: reflectance = base colour, no Fresnel.
        return {"type": "conductor", "material": "none", "specular_reflectance": {"type": "rgb", "value": base}}
    if m.get("extras", {}).get("photonlab", {}).get("bsdf") == "lambertian":
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": base}}
    sys.exit(f"material '{m.get('name')}' has no Mitsuba counterpart here")


def write_ply(path, positions, normals, faces):
    with open(path, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\n")
        f.write(b"element vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(positions))
        if normals is not None:
            f.write(b"property float nx\nproperty float ny\nproperty float nz\n")
        f.write(b"element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        v = positions.astype("<f4") if normals is None else np.hstack([positions, normals]).astype("<f4")
        f.write(v.tobytes())
        tri = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
        tri["n"], tri["i"] = 3, faces
        f.write(tri.tobytes())


def mitsuba_scene(gltf, width, max_depth, tmp, sampler="independent"):
    meshes, materials, camera = read_gltf(gltf)
    scene = {"type": "scene"}
    for k, (p, n, i, mat) in enumerate(meshes):
        ply = os.path.join(tmp, f"mesh{k}.ply")
        write_ply(ply, p, n, i)
        m = materials[mat]
        shape = {"type": "ply", "filename": ply, "face_normals": n is None}
        emission = m.get("emissiveFactor")
        if emission and max(emission) > 0:
            strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": [e * strength for e in emission]}}
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
        else:
            shape["bsdf"] = mitsuba_bsdf(m)
        scene[f"shape{k}"] = shape
    origin, forward, up, yfov = camera
    import mitsuba as mi
    scene["camera"] = {
        "type": "perspective", "fov": math.degrees(yfov), "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(origin=origin, target=[origin[i] + forward[i] for i in range(3)], up=up),
        "film": {"type": "hdrfilm", "width": width, "height": width, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        "sampler": {"type": sampler}}
    scene["integrator"] = {"type": "path", "max_depth": max_depth + 1}
    return scene


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--photonlab", default="build/photonlab")
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--spp", type=int, default=4, help="samples per pixel of each image")
    ap.add_argument("--images", type=int, default=64, help="independent images per estimate")
    ap.add_argument("--depths", default="1,2,3,4,5,6,8,10,16,64")
    ap.add_argument("--save", help="write both renderers' mean images at the last depth as NAME-{photonlab,mitsuba}.npy")
    a = ap.parse_args(argv)
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    depths = [int(d) for d in a.depths.split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        masks = None
        for d in depths:
            scene = mi.load_dict(mitsuba_scene(a.scene, a.width, d, tmp))
            mit, pl = [], []
            for k in range(a.images):
                mit.append(np.array(mi.render(scene, spp=a.spp, seed=1000 + k)))
                out = os.path.join(tmp, "pl.exr")
                subprocess.run([a.photonlab, "render", a.scene, "--integrator", "path", "--width", str(a.width),
                                "--spp", str(a.spp), "--max-depth", str(d), "--seed", str(1 + k), "-q", "-o", out],
                               check=True)
                pl.append(np.array(mi.Bitmap(out))[:, :, :3])
            mit, pl = np.array(mit).mean(axis=3), np.array(pl).mean(axis=3)  # luminance-like grey
            if masks is None:
                # Pixels that see an emitter directly (mean above 1 in either renderer) are left
                # out: their variance is the pixel's coverage of the emitter, Le² p(1 − p), the same
                # in both, and a few of them would dominate every sum. "Indirect": the pixels
                # that the first depth leaves black (at depth 1, no direct light reaches them).
                emitter = (mit.mean(axis=0) > 1) | (pl.mean(axis=0) > 1)
                unlit = (mit.mean(axis=0) == 0) & (pl.mean(axis=0) == 0)
                masks = {"all": ~emitter, "indirect": unlit & ~emitter}
            row = {"depth": d}
            for name, imgs in (("photonlab", pl), ("mitsuba", mit)):
                var = imgs.var(axis=0, ddof=1) * a.spp
                row[name] = {m: (imgs.mean(axis=0)[mask].mean(), var[mask].mean()) for m, mask in masks.items()}
            rows.append(row)
            line = f"depth {d:3d}"
            for m in masks:
                (pm_, pv), (mm_, mv) = row["photonlab"][m], row["mitsuba"][m]
                line += (f"  | {m} ({masks[m].sum()} px): mean {pm_:.5f} / {mm_:.5f}"
                         f"  var/sample {pv:.5f} / {mv:.5f} = {pv / mv if mv > 0 else float('nan'):.3f}")
            print(line, flush=True)
            if a.save and d == depths[-1]:
                np.save(a.save + "-photonlab.npy", pl.mean(axis=0))
                np.save(a.save + "-mitsuba.npy", mit.mean(axis=0))
    print()
    print(markdown_table(rows))
    return rows


def markdown_table(rows):
    """The ratios per depth as the results page shows them (scripts/results_pages.py --table mitsuba-variance)."""
    lines = ["| max depth | all pixels: photonlab / Mitsuba variance | indirect pixels |", "|---|---|---|"]
    for row in rows:
        cells = []
        for m in ("all", "indirect"):
            (pmean, pv), (mmean, mv) = row["photonlab"][m], row["mitsuba"][m]
            cells.append(f"{pv / mv:.3f}" if mv > 0 else "(black)")
        lines.append(f"| {row['depth']} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
