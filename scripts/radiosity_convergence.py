#!/usr/bin/python3
"""Radiosity's error against the path tracer as the patches get smaller (docs: results/radiosity.md, Classic
radiosity): renders SCENE with `--integrator radiosity` at each patch budget, in smooth display
(the solution alone) and with the final gather, and compares each with a long path-traced
reference: relMSE over the image, and the worst and mean error over 4×4 regions (relative to
the region's level, or to a tenth of the mean region's in dark regions, as the test does).
Writes FIGURE.png and prints a Markdown table with the solve times photonlab reported.

    scripts/radiosity_convergence.py [--scene S] [--width W] [--budgets 250,1000,...]
        [--regions 4] [--reference-spp N] [--gather-spp N] [--out DIR] [--figure FIG.png]
"""
import argparse
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NOTE = re.compile(r"radiosity: (\d+) patches .*form factors ([0-9.]+) s .*Gauss-Seidel ([0-9.]+) s")


def render(binary, scene, out, width, args):
    cmd = [binary, "render", scene, "-o", out, "--width", str(width)] + args
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("radiosity_convergence: %s failed: %s" % (" ".join(cmd), r.stderr.strip().splitlines()[-1:]))
    return r.stderr


def region_errors(image, reference, regions=4):
    by, bx = reference.shape[0] // regions, reference.shape[1] // regions
    h, w = by * regions, bx * regions

    def sums(a):
        return a[:h, :w].sum(axis=2).reshape(regions, by, regions, bx).sum(axis=(1, 3))

    a, p = sums(image), sums(reference)
    floor = 0.1 * p.mean()
    return np.abs(a - p) / np.maximum(p, floor)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "photonlab"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell-box.gltf"))
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--budgets", default="250,500,1000,2000,4000,8000,16000")
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--gather-spp", type=int, default=256)
    ap.add_argument("--smooth-spp", type=int, default=64)
    ap.add_argument("--regions", type=int, default=4, help="regions per side")
    ap.add_argument("--out", default="results/radiosity-convergence")
    ap.add_argument("--figure", default=None, help="default: OUT/radiosity-patches.png")
    a = ap.parse_args(argv)
    if not os.path.isfile(a.binary):
        sys.exit("radiosity_convergence: no photonlab binary at %s (build first, or --binary)" % a.binary)
    budgets = [int(b) for b in a.budgets.split(",")]
    os.makedirs(a.out, exist_ok=True)
    ref_path = os.path.join(a.out, "reference-path-%d-%dspp.exr" % (a.width, a.reference_spp))
    if not os.path.isfile(ref_path):
        render(a.binary, a.scene, ref_path, a.width, ["--integrator", "path", "--spp", str(a.reference_spp), "--seed", "1000"])
    reference = er.read_exr(ref_path)
    rows = []
    for budget in budgets:
        row = {"budget": budget}
        for display, spp in (("smooth", a.smooth_spp), ("gather", a.gather_spp)):
            out = os.path.join(a.out, "radiosity-%d-%s.exr" % (budget, display))
            log = render(a.binary, a.scene, out, a.width,
                         ["--integrator", "radiosity", "--patches", str(budget), "--display", display, "--spp", str(spp)])
            m = NOTE.search(log)
            if not m:
                sys.exit("radiosity_convergence: photonlab did not report its patches: " + log.strip())
            row["patches"], row["form_factors"], row["solve"] = int(m.group(1)), float(m.group(2)), float(m.group(3))
            image = er.read_exr(out)
            errors = region_errors(image, reference, a.regions)
            row[display] = {"worst": float(errors.max()), "mean": float(errors.mean()),
                            "relmse": float(np.mean(er.relmse_map(image, reference)))}
        rows.append(row)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    patches = [r["patches"] for r in rows]
    for display, colour in (("smooth", "tab:blue"), ("gather", "tab:orange")):
        ax.loglog(patches, [100 * r[display]["mean"] for r in rows], "o-", color=colour, label=display + ": mean region")
        ax.loglog(patches, [100 * r[display]["worst"] for r in rows], "s--", color=colour, label=display + ": worst region")
    ax.axhline(3, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("patches")
    ax.set_ylabel("error against the path tracer (%)")
    ax.set_title("Radiosity on %s, %d px wide, %dx%d regions" % (os.path.basename(a.scene), a.width, a.regions, a.regions),
                 fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    figure = a.figure or os.path.join(a.out, "radiosity-patches.png")
    fig.savefig(figure, dpi=90)

    print("| patches | form factors (s) | Gauss-Seidel (s) | smooth: worst / mean region, relMSE | gather: worst / mean region, relMSE |")
    print("|---|---|---|---|---|")
    for r in rows:
        print("| %d | %.2f | %.2f | %.1f%% / %.2f%%, %.4f | %.1f%% / %.2f%%, %.4f |" % (
            r["patches"], r["form_factors"], r["solve"], 100 * r["smooth"]["worst"], 100 * r["smooth"]["mean"],
            r["smooth"]["relmse"], 100 * r["gather"]["worst"], 100 * r["gather"]["mean"], r["gather"]["relmse"]))
    print(figure)


if __name__ == "__main__":
    main()
