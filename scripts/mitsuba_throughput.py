#!/usr/bin/env python3
"""Path-traced samples per second and equal-time error, photonlab against Mitsuba 3, interleaved.

Issue 20's comparison, reproducible: each scene (a photonlab glTF written by make_scenes.py,
converted for Mitsuba by mitsuba_variance.py: PLY meshes with the same normals, the same camera,
box filter, independent sampler, `path` with next-event estimation and MIS, Mitsuba's max_depth
= photonlab's --max-depth + 1) is rendered by both renderers in turn, round after round, on every
core of this machine, at the same resolution and sample count.

  samples/s   pixels × spp over the render's own time: photonlab's, recorded in its image (scene
              loading and process start-up excluded), Mitsuba's mi.render() after one warm-up render that
              compiles its kernels (excluded likewise). Min and max over the rounds.
  relMSE      at equal time (--equal-time, seconds): photonlab `render --time T`; Mitsuba the spp
              its median rate gives in T, rescaled by T over its time and rendered again while
              that time is more than 5% from T (at most three renders; its time is reported).
              Against a photonlab path-traced reference of --reference-spp samples per pixel
              (seed 1000, independent of the runs'), by `photonlab compare` (per channel,
              (a − b)²/(b² + 0.01)). The reference's own relMSE adds the same amount to both.

Needs Mitsuba 3 and numpy in the interpreter that runs it, and DRJIT_LIBLLVM_PATH at a libLLVM ≥ 16
(Debian 12: apt install libllvm19):

  python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
  DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so venv/bin/python \\
      scripts/mitsuba_throughput.py scenes/cornell-spheres.gltf scenes/cornell-box.gltf
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def photonlab_render(exe, scene, width, out, spp=None, seconds=None, seed=1, max_depth=64, sampler="independent"):
    cmd = [exe, "render", scene, "--integrator", "path", "--width", str(width), "--max-depth", str(max_depth),
           "--seed", str(seed), "--sampler", sampler, "-o", out]
    cmd += ["--spp", str(spp)] if spp else ["--time", str(seconds)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{exe}: {r.stderr.strip()}")
    # The image's own record (`photonlab info`): the render's seconds at full precision (the
    # summary line rounds them to 10 ms), its samples per pixel (fractional under --time) and size.
    info = json.loads(subprocess.run([exe, "info", out], capture_output=True, text=True, check=True).stdout)
    samples, secs = float(info["spp"]), float(info["seconds"])
    return info["width"] * info["height"] * samples / secs, secs, samples


def render_for_time(render, seconds, spp, round_spp=lambda n: n, tolerance=0.05, tries=3):
    """Render with `spp` samples per pixel, and again with the count scaled by seconds / its
    time while the render missed `seconds` by more than `tolerance` (at most `tries` renders):
    a renderer's rate at hundreds of samples per pixel need not be its rate at a few dozen, and
    an equal-time comparison is only equal if the times are. `render(spp)` returns (image,
    seconds); `round_spp` maps a count to one the sampler accepts. Returns (image, seconds, spp)
    of the last render."""
    for k in range(tries):
        img, secs = render(spp)
        if abs(secs - seconds) <= tolerance * seconds or k == tries - 1:
            break
        scaled = round_spp(max(1, round(spp * seconds / secs)))
        if scaled == spp:
            break
        spp = scaled
    return img, secs, spp


def relmse(exe, image, reference):
    r = subprocess.run([exe, "compare", image, reference], capture_output=True, text=True, check=True)
    return float(re.search(r'"relmse": ([0-9.e+-]+)', r.stdout).group(1))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--photonlab", default="build/photonlab")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel of each throughput render")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--max-depth", type=int, default=64, help="photonlab's; Mitsuba's max_depth is one more")
    ap.add_argument("--equal-time", default="10,30", help="seconds for the equal-time relMSE ('' to skip)")
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--sampler", default="independent", choices=["independent", "sobol"],
                    help="photonlab's --sampler for the runs (the reference is always independent)")
    ap.add_argument("--mitsuba-sampler", default="independent",
                    help="Mitsuba's sampler plugin: independent, stratified, multijitter, orthogonal, ldsampler")
    a = ap.parse_args(argv)
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    from mitsuba_variance import mitsuba_scene

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for path in a.scenes:
            name = os.path.basename(path)
            scene = mi.load_dict(mitsuba_scene(path, a.width, a.max_depth, tmp, a.mitsuba_sampler))
            height = scene.sensors()[0].film().size()[1]
            pixels = a.width * height

            def mitsuba_render(spp, seed):
                t = time.perf_counter()
                img = mi.render(scene, spp=spp, seed=seed)
                dr.eval(img)
                dr.sync_thread()
                return img, time.perf_counter() - t

            mitsuba_render(a.spp, 0)  # compiles the kernels
            pl, mt = [], []
            for k in range(a.rounds):
                pl.append(photonlab_render(a.photonlab, path, a.width, os.path.join(tmp, "p.exr"), spp=a.spp,
                                           seed=k + 1, max_depth=a.max_depth, sampler=a.sampler)[0])
                _, secs = mitsuba_render(a.spp, k + 1)
                mt.append(pixels * a.spp / secs)
                print(f"{name} round {k + 1}: photonlab {pl[-1] / 1e6:.2f} M samples/s, Mitsuba {mt[-1] / 1e6:.2f} M",
                      flush=True)
            row = {"scene": name, "size": f"{a.width}x{height}", "photonlab": pl, "mitsuba": mt, "times": []}
            if a.equal_time:
                ref = os.path.join(tmp, "ref.exr")
                photonlab_render(a.photonlab, path, a.width, ref, spp=a.reference_spp, seed=1000, max_depth=a.max_depth)
                for seconds in [float(s) for s in a.equal_time.split(",")]:
                    _, _, pspp = photonlab_render(a.photonlab, path, a.width, os.path.join(tmp, "p.exr"),
                                                  seconds=seconds, seed=1, max_depth=a.max_depth, sampler=a.sampler)
                    e_pl = relmse(a.photonlab, os.path.join(tmp, "p.exr"), ref)
                    mspp = max(1, round(statistics.median(mt) * seconds / pixels))
                    # A stratified sampler takes the count it can stratify (multijitter: the next
                    # product of two near-equal integers; ldsampler: a power of 4): render that many
                    # and report its time, rather than have Mitsuba round it silently.
                    # Mitsuba's rate at hundreds of samples per pixel is below its rate at --spp
                    # (its renders overran T by 20-30%): rescale the count until the time is T.
                    def accepted(n):
                        return mi.load_dict({"type": a.mitsuba_sampler, "sample_count": n}).sample_count()
                    img, msecs, mspp = render_for_time(lambda n: mitsuba_render(n, 1), seconds, accepted(mspp),
                                                       accepted)
                    mi.Bitmap(img).write(os.path.join(tmp, "m.exr"))
                    e_mt = relmse(a.photonlab, os.path.join(tmp, "m.exr"), ref)
                    row["times"].append((seconds, pspp, e_pl, mspp, msecs, e_mt))
                    print(f"{name} {seconds:g} s: photonlab {pspp:.0f} spp relMSE {e_pl:.5g}; "
                          f"Mitsuba {mspp} spp in {msecs:.1f} s relMSE {e_mt:.5g}", flush=True)
            rows.append(row)

    print()
    print("| scene | size | photonlab M samples/s | Mitsuba M samples/s | ratio (medians) |")
    print("|---|---|---|---|---|")
    for r in rows:
        p, m = r["photonlab"], r["mitsuba"]
        print(f"| {r['scene']} | {r['size']} | {min(p) / 1e6:.2f}–{max(p) / 1e6:.2f} | {min(m) / 1e6:.2f}–{max(m) / 1e6:.2f} "
              f"| {statistics.median(p) / statistics.median(m):.2f} |")
    if any(r["times"] for r in rows):
        print()
        # The last column holds when Mitsuba's render did not take T (its rate at many samples per
        # pixel is not its rate at --spp, or its sampler rounded the count): an unbiased estimate's
        # relMSE falls as 1/time, so relMSE × seconds compares the two at equal time.
        print("| scene | time | photonlab spp | photonlab relMSE | Mitsuba spp (its seconds) | Mitsuba relMSE | ratio "
              "| ratio of relMSE × seconds |")
        print("|---|---|---|---|---|---|---|---|")
        for r in rows:
            for seconds, pspp, e_pl, mspp, msecs, e_mt in r["times"]:
                print(f"| {r['scene']} | {seconds:g} s | {pspp:.0f} | {e_pl:.5g} | {mspp} ({msecs:.1f} s) | {e_mt:.5g} "
                      f"| {e_pl / e_mt:.2f} | {e_pl * seconds / (e_mt * msecs):.2f} |")
    return rows


if __name__ == "__main__":
    main()
