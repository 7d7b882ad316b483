#!/usr/bin/env python3
"""Each sampler's error at equal samples per pixel, photonlab's and Mitsuba 3's.

Renders one scene with photonlab's path tracer for each of its --sampler values and with
Mitsuba 3's `path` for each of its sampler plugins (the scene converted as mitsuba_variance.py
converts it: same meshes, normals, camera, box filter, NEE with MIS, max_depth = photonlab's + 1),
all at --spp samples per pixel and for each seed, and prints every image's relMSE against one
reference: --reference, or a photonlab path-traced render of --reference-spp samples per pixel
(seed 1000, independent of the runs'). At equal samples the two path tracers' estimators are the
same (docs: results/mitsuba.md, the variance study), so what differs between rows is the samplers.

Needs Mitsuba 3 and numpy in the interpreter that runs it, and DRJIT_LIBLLVM_PATH at a libLLVM ≥ 16:

  DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so venv/bin/python \\
      scripts/mitsuba_samplers.py scenes/cornell-box.gltf --spp 256
"""
import argparse
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mitsuba_throughput import photonlab_render, relmse  # noqa: E402


def photonlab_rows(exe, scene, width, spp, seeds, samplers, reference, tmp, max_depth=64):
    """(renderer, sampler, seed, relMSE) of photonlab's path tracer for each sampler and seed."""
    rows = []
    for seed in seeds:
        for sampler in samplers:
            out = os.path.join(tmp, f"photonlab-{sampler}-{seed}.exr")
            photonlab_render(exe, scene, width, out, spp=spp, seed=seed, max_depth=max_depth, sampler=sampler)
            rows.append(("photonlab", sampler, seed, relmse(exe, out, reference)))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--photonlab", default="build/photonlab")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--spp", type=int, default=256, help="a power of 4 suits every Mitsuba sampler")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--max-depth", type=int, default=64, help="photonlab's; Mitsuba's max_depth is one more")
    ap.add_argument("--samplers", default="independent,sobol", help="photonlab's --sampler values")
    ap.add_argument("--mitsuba-samplers", default="independent,ldsampler,stratified,multijitter")
    ap.add_argument("--reference", help="an EXR of the same size (default: render one)")
    ap.add_argument("--reference-spp", type=int, default=8192)
    a = ap.parse_args(argv)
    seeds = [int(s) for s in a.seeds.split(",")]
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    from mitsuba_variance import mitsuba_scene

    with tempfile.TemporaryDirectory() as tmp:
        reference = a.reference
        if not reference:
            reference = os.path.join(tmp, "reference.exr")
            photonlab_render(a.photonlab, a.scene, a.width, reference, spp=a.reference_spp, seed=1000,
                             max_depth=a.max_depth)
        rows = photonlab_rows(a.photonlab, a.scene, a.width, a.spp, seeds, a.samplers.split(","), reference, tmp,
                              a.max_depth)
        for sampler in a.mitsuba_samplers.split(","):
            scene = mi.load_dict(mitsuba_scene(a.scene, a.width, a.max_depth, tmp, sampler))
            count = mi.load_dict({"type": sampler, "sample_count": a.spp}).sample_count()
            if count != a.spp:
                sys.exit(f"mitsuba_samplers.py: --spp: Mitsuba's {sampler} takes {count}, not {a.spp}; use a power of 4")
            for seed in seeds:
                out = os.path.join(tmp, f"mitsuba-{sampler}-{seed}.exr")
                mi.Bitmap(mi.render(scene, spp=a.spp, seed=seed)).write(out)
                rows.append(("Mitsuba", sampler, seed, relmse(a.photonlab, out, reference)))

    print(f"| {os.path.basename(a.scene)}, {a.spp} spp | relMSE (seeds {', '.join(map(str, seeds))}) |")
    print("|---|---|")
    for renderer in ("photonlab", "Mitsuba"):
        for sampler in dict.fromkeys(r[1] for r in rows if r[0] == renderer):
            values = [f"{r[3]:.3g}" for r in rows if r[0] == renderer and r[1] == sampler]
            print(f"| {renderer}, `{sampler}` | {', '.join(values)} |")
    return rows


if __name__ == "__main__":
    main()
