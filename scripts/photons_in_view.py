#!/usr/bin/python3
"""Photons where the camera looks, measured: the progressive photon-mapping methods against the
path tracer at equal time on views where few photons land near what the camera sees (Khronos
models under the default sky, and sky.gltf's glass sphere seen close up), each with uniform and
adaptive photon sampling. The results page docs/pages/results/photons-in-view.md shows its table.

For each view: a long path-traced reference (cached in --cache), then, seed by seed and
interleaved, the path tracer, sppm and pppm with --photon-sampling uniform and adaptive, each
for --time seconds. A row gives the relMSE against the reference as the mean over seeds (what
one run gets) with its range, its ratio to the path tracer's mean, and the fraction of usable
photons that landed near a visible point (`visible_photons`, mean over seeds).

    /usr/bin/python3 scripts/photons_in_view.py --source ~/glTF-Sample-Assets/Models \\
        --width 256 --time 30 --seeds 1 2 --out results/photons-in-view
    /usr/bin/python3 scripts/results_pages.py --table photons-in-view results/photons-in-view/table.md

--source is a folder laid out as glTF-Sample-Assets' Models/, or a URL of that layout (by
default the repository on GitHub; the models are downloaded into --cache). --views restricts
the views by name.
"""
import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402
import gallery  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# (name, Khronos model or a shipped scene's path, extra view options)
VIEWS = [
    ("DamagedHelmet", "DamagedHelmet", []),
    ("CesiumMilkTruck", "CesiumMilkTruck", []),
    ("sky.gltf, glass sphere close up", os.path.join(ROOT, "scenes", "sky.gltf"),
     ["--look-from", "1.2,0.9,2.2", "--look-at", "1.2,0.2,0", "--fov", "22"]),
]
METHODS = [("path", "path", []),
           ("sppm, uniform", "sppm", ["--photon-sampling", "uniform"]),
           ("sppm, adaptive", "sppm", ["--photon-sampling", "adaptive"]),
           ("pppm, uniform", "pppm", ["--photon-sampling", "uniform"]),
           ("pppm, adaptive", "pppm", ["--photon-sampling", "adaptive"])]


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise SystemExit(f"photons_in_view: {' '.join(cmd)} failed: {r.stderr.strip().splitlines()[-1:]}")
    return r


def relmse(photonlab, image, reference):
    return float(json.loads(run([photonlab, "compare", image, reference]).stdout)["relmse"])


def table(rows, args):
    """Markdown: one row per view and method."""
    lines = [f"| view | method | relMSE, mean over {len(args.seeds)} seeds | range | × path tracer | photons near a visible point |",
             "|---|---|---|---|---|---|"]
    for view, results in rows:
        path_mean = sum(results["path"][0]) / len(results["path"][0])
        for label, _, _ in METHODS:
            errors, visible = results[label]
            mean = sum(errors) / len(errors)
            vis = f"{100 * sum(visible) / len(visible):.1f}%" if visible else ""
            lines.append(f"| {view} | {label} | {mean:.3g} | {min(errors):.3g}–{max(errors):.3g} | "
                         f"{mean / path_mean:.2f} | {vis} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--photonlab", default=os.path.join(ROOT, "build", "photonlab"))
    ap.add_argument("--source", default=gallery.KHRONOS)
    ap.add_argument("--cache", default=os.path.join(ROOT, "results", "cache"))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "photons-in-view"))
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--time", type=float, default=30)
    ap.add_argument("--reference-time", type=float, default=1200, help="the path-traced reference's seconds")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--views", nargs="*", help="only these views (their names' first word)")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    os.makedirs(args.cache, exist_ok=True)
    rows = []
    for name, model, extra in VIEWS:
        if args.views and name.split(",")[0] not in args.views:
            continue
        scene = model if os.path.isfile(model) else (
            gallery.local_model(args.source, model) if os.path.isdir(args.source) else gallery.fetch_model(args.source, args.cache, model))
        if not scene:
            raise SystemExit(f"photons_in_view: {model}: not found in {args.source}")
        key = name.split(",")[0].replace(".", "-")
        size = ["--width", str(args.width)]
        ref = os.path.join(args.cache, f"reference-{key}-{args.width}-{args.reference_time:g}s.exr")
        if not os.path.isfile(ref):
            print(f"{name}: path-traced reference, {args.reference_time:g} s", file=sys.stderr)
            run([args.photonlab, "render", scene, *extra, *size, "--integrator", "path", "--time", str(args.reference_time),
                 "--seed", "1000", "-q", "-o", ref])
        results = {label: ([], []) for label, _, _ in METHODS}
        for seed in args.seeds:
            for label, integrator, options in METHODS:  # interleaved: every method once per seed
                out = os.path.join(args.out, f"{key}-{label.replace(', ', '-')}-{seed}.exr")
                run([args.photonlab, "render", scene, *extra, *size, "--integrator", integrator, *options,
                     "--time", str(args.time), "--seed", str(seed), "-q", "-o", out])
                errors, visible = results[label]
                errors.append(relmse(args.photonlab, out, ref))
                meta = er.read_image_metadata(out)
                if "visible_photons" in meta:
                    visible.append(float(meta["visible_photons"]))
                print(f"{name}, {label}, seed {seed}: relMSE {errors[-1]:.3g}", file=sys.stderr)
        rows.append((name, results))
    text = table(rows, args)
    path = os.path.join(args.out, "table.md")
    with open(path, "w", encoding="utf-8") as f:
        f.write(f"{args.width} pixels wide, {args.time:g} s per run, {os.cpu_count()} threads; "
                f"references: the path tracer for {args.reference_time:g} s.\n\n" + text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
