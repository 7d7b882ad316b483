#!/usr/bin/env python3
"""photonlab's bidirectional methods beside SmallVCM's, on SmallVCM's own scenes, interleaved.

SmallVCM (Davidovič & Georgiev, github.com/SmallVCM/SmallVCM) is the reference implementation of
vertex connection and merging. This script builds it from a checkout (g++ -O3 -fopenmp, with two
lines changed: it prints its iteration count, and takes its seed from SMALLVCM_SEED, so that
repeats are independent runs as photonlab's seeds are; its own is fixed at 1234, which its
reference keeps, so runs use 2000, 2100, ...), then renders SmallVCM's scene 0 (glossy
Cornell box, mirror and glass spheres, directional "sun") and scene 2 (the same lit by a point
light) with every method of both codebases for the same wall time at 512², 2 threads, one
method of each codebase after the other so that both see the same machine state. photonlab
renders scenes/smallvcm-sun.gltf and scenes/smallvcm-point.gltf, the same scenes in glTF
(scripts/make_scenes.py; the spheres tessellated), with max_depth 9 (SmallVCM's 10 path
segments).

Each image's relMSE (photonlab compare's: mean of (x − r)²/(r² + 0.01)) is measured against a long
reference of its own codebase: SmallVCM's images against a long SmallVCM vcm render, photonlab's
against a long photonlab vcm render (1024 iterations, seed 1000; the geometry differs by the
tessellation, so neither is the other's answer). The references are rendered first unless they
are in OUT already.

Beside each mean relMSE the table gives the mean over each image's best 99% of pixels (the bulk
of the error, without the few single samples that decide a 20 s run) and every run's values.
Where both codebases ran a pair, a second table gives photonlab's mean over SmallVCM's with a
90% bootstrap interval over the runs (ratio_of_means), the ratio of the medians with its own
interval (ratio_of_medians: the one that exists where single samples have no finite variance,
as bdpt's under the point light, see --tail), and the ratio of the best-99% means.

Run k renders with photonlab seed k + 1 and SmallVCM seed 2000 + 100 k (each of its threads adds
its number). Runs are therefore repeatable, and two comparisons with the same runs draw the same
samples: the same fireflies, within the iterations both reach. --first-run K starts at run K,
for samples no earlier comparison drew.

SmallVCM's -t counts process CPU seconds (clock()), so it gets -t 2·seconds for about `seconds`
of wall time on 2 cores; the wall time each run took is measured here and reported.

With --tail N it measures instead how often each method's single samples are fireflies: N
renders of one iteration each per codebase (interleaved, seeds all distinct), and in each the
pixels brighter than 50, 100, 200, 500 and 1000 (largest channel). One iteration's image is its
samples, so a pixel above 50 where the image averages 0.5 is one sample of that size: the counts
per 100 iterations compare the two estimators' tails directly, with no reference and none of the
luck that a few 20 s renders leave to whether a rare large sample fell in them. It also fits
the tail's Pareto index α to the samples above 50 and above 100 (tail_index): α ≤ 2 is a tail
with no finite variance.

Usage: python3 scripts/compare_smallvcm.py --smallvcm-src DIR [--seconds 20] [--reference-iterations 1024]
       [--reference-seconds 600]
       [--repeats 1] [--first-run 0] [--methods bdpt:bpt,vcm:vcm] [--out DIR] [--tail N] [--photonlab-args "--heuristic balance"]
Prints a Markdown table (and writes it to OUT/table.md, or OUT/tail.md).
"""
import argparse
import json
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results  # noqa: E402  (the one uncached image reader)

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SCENES = {"sun": 0, "point": 2}
# photonlab method : SmallVCM method ("" where the other codebase has no such method).
# Jensen's photon map (`photon`) is left out: it is not progressive, and at 512² its final
# gather alone outlasts 20 s.
PAIRS = [("path", "pt"), ("light", "lt"), ("ppm", "ppm"), ("bpm", "bpm"), ("bdpt", "bpt"), ("vcm", "vcm"),
         ("sppm", ""), ("pppm", "")]


def build_smallvcm(src, out):
    """Copies SmallVCM's source to OUT/smallvcm-src, makes it print its iteration count, builds it."""
    work = os.path.join(out, "smallvcm-src")
    if os.path.exists(work):
        shutil.rmtree(work)
    shutil.copytree(src, work)
    main = os.path.join(work, "src", "smallvcm.cxx")
    text = open(main).read()
    patched = text.replace("float time = render(config);\n    printf(\"done in %.2f s\\n\", time);",
                           "int iterations = 0;\n    float time = render(config, &iterations);\n"
                           "    printf(\"done in %.2f s, %d iterations\\n\", time, iterations - 1);")
    if patched == text:
        sys.exit("compare_smallvcm: %s: unrecognised src/smallvcm.cxx (cannot report iterations)" % src)
    open(main, "w").write(patched)
    config = os.path.join(work, "src", "config.hxx")
    text = open(config).read()
    patched = text.replace("oConfig.mBaseSeed      = 1234;",
                           "oConfig.mBaseSeed      = getenv(\"SMALLVCM_SEED\") ? atoi(getenv(\"SMALLVCM_SEED\")) : 1234;")
    if patched == text:
        sys.exit("compare_smallvcm: %s: unrecognised src/config.hxx (cannot set the seed)" % src)
    open(config, "w").write("#include <cstdlib>\n" + patched)
    binary = os.path.join(out, "smallvcm")
    subprocess.run(["g++", "-O3", "-fopenmp", "-o", binary, main], check=True)
    return binary


def run_photonlab(photonlab, scene, method, seconds, output, seed=1, spp=0, extra=()):
    budget = ["--spp", str(spp)] if spp else ["--time", str(seconds)]
    args = [photonlab, "render", os.path.join(ROOT, "scenes", "smallvcm-%s.gltf" % scene), "--integrator", method,
            "--width", "512", "--threads", "2", "--seed", str(seed), "-o", output, "-q"] + budget
    args += ["--max-depth", "9"] + list(extra)
    start = time.monotonic()
    subprocess.run(args, check=True)
    wall = time.monotonic() - start
    meta = json.loads(subprocess.run([photonlab, "info", output], check=True, capture_output=True, text=True).stdout)
    work = meta.get("passes") or meta.get("spp")
    return wall, "%s %s" % (work, "passes" if "passes" in meta else "iterations" if method in ("bdpt", "bpm", "vcm", "light") else "spp")


def run_smallvcm(binary, scene, method, seconds, output, seed=1234):
    start = time.monotonic()
    r = subprocess.run([binary, "-s", str(SCENES[scene]), "-a", method, "-t", str(2 * seconds), "-o", output],
                       check=True, capture_output=True, text=True, env=dict(os.environ, SMALLVCM_SEED=str(seed)))
    wall = time.monotonic() - start
    m = re.search(r"(\d+) iterations", r.stdout)
    return wall, "%s iterations" % (m.group(1) if m else "?")


TAIL_THRESHOLDS = (50, 100, 200, 500, 1000)


def count_above(path, thresholds=TAIL_THRESHOLDS):
    """(pixels whose largest channel exceeds each threshold, the image's mean, the values above
    the lowest threshold) of an EXR or HDR image."""
    rgb = read_rgb(path)
    largest = rgb.max(axis=-1)
    return ([int((largest > t).sum()) for t in thresholds], float(rgb.mean()),
            [float(v) for v in largest[largest > thresholds[0]]])


def tail_index(values, u):
    """The Pareto tail index α of the samples above u, by maximum likelihood (Hill 1975):
    P(X > x | X > u) = (x/u)^−α gives α̂ = n / Σ ln(x_i/u), with standard error α̂/√n.
    α ≤ 2 means the samples have no finite variance: then the squared error of an n-sample mean
    has no finite expectation (its tail is x^−α/2), and a mean of per-run relMSE does not
    settle as runs are added; the median of runs does."""
    import math
    logs = [math.log(v / u) for v in values if v > u]
    if not logs or sum(logs) <= 0:
        return float("nan"), float("nan"), len(logs)
    alpha = len(logs) / sum(logs)
    return alpha, alpha / math.sqrt(len(logs)), len(logs)


def tail_table(counts, iterations, thresholds=TAIL_THRESHOLDS):
    """Markdown rows: per (scene, code, method), samples above each threshold per 100 iterations,
    with the Poisson standard error of the count (sqrt n)."""
    fits = thresholds[:2]
    rows = ["| scene | code | method | iterations | mean | " + " | ".join("> %g" % t for t in thresholds) + " | " +
            " | ".join("tail index α above %g" % u for u in fits) + " |",
            "|---|---|---|---|---|" + "---|" * (len(thresholds) + len(fits))]
    for (scene, code, method), (totals, mean, values) in counts.items():
        cells = ["%.1f ± %.1f" % (100.0 * n / iterations, 100.0 * n ** 0.5 / iterations) for n in totals]
        cells += ["%.2f ± %.2f (%d)" % tail_index(values, u) for u in fits]
        rows.append("| %s | %s | `%s` | %d | %.4f | %s |" % (scene, code, method, iterations, mean / iterations,
                                                             " | ".join(cells)))
    return "\n".join(rows) + "\n"


def run_tail(a, binary, pairs):
    """--tail N: N single-iteration renders per codebase and method, interleaved; firefly counts."""
    counts = {}
    for scene in a.scenes.split(","):
        for ours, theirs in pairs:
            for k in range(a.tail):
                for code, method in (("photonlab", ours), ("SmallVCM", theirs)):
                    if not method:
                        continue
                    if code == "photonlab":
                        out = os.path.join(a.out, "tail-photonlab.exr")
                        run_photonlab(a.photonlab, scene, method, 0, out, seed=10000 + k, spp=1,
                                      extra=shlex.split(a.photonlab_args))
                    else:
                        out = os.path.join(a.out, "tail-smallvcm.hdr")
                        subprocess.run([binary, "-s", str(SCENES[scene]), "-a", method, "-i", "1", "-o", out], check=True,
                                       capture_output=True, env=dict(os.environ, SMALLVCM_SEED=str(30000 + k)))
                    above, mean, values = count_above(out)
                    totals, means, kept = counts.setdefault((scene, code, method), ([0] * len(above), 0.0, []))
                    counts[(scene, code, method)] = ([x + y for x, y in zip(totals, above)], means + mean, kept + values)
    text = tail_table(counts, a.tail)
    open(os.path.join(a.out, "tail.md"), "w").write(text)
    print(text)


def read_rgb(path):
    """Linear RGB of an EXR or HDR image, read uncached (experiment_results.read_exr)."""
    try:
        return experiment_results.read_exr(path)
    except experiment_results.ResultsError as e:
        sys.exit("compare_smallvcm: %s" % e)


def trimmed_relmse(image, reference, keep=0.99):
    """photonlab compare's per-pixel relMSE, (x − r)²/(r² + 0.01) averaged over a pixel's
    channels, then over the image's best `keep` of pixels: the bulk of the error without the
    few single samples that decide a short run's whole-image relMSE."""
    import numpy as np
    x, r = read_rgb(image), read_rgb(reference)
    per_pixel = np.sort(((x - r) ** 2 / (r * r + 0.01)).mean(axis=-1).ravel())
    return float(per_pixel[:int(per_pixel.size * keep)].mean())


def ratio_of_means(ours, theirs, resamples=10000, level=0.90, seed=1):
    """mean(ours) / mean(theirs) of two lists of per-run relMSE, with a percentile bootstrap
    interval at `level`: each resample draws both lists' runs again with replacement (each
    codebase's runs are its own independent draws). A few runs that caught a large firefly
    decide a short render's relMSE, so the interval, not the ratio alone, says whether a
    target such as 0.8 is shown. A fixed seed: the same runs give the same interval."""
    return bootstrap_ratio(ours, theirs, "mean", resamples, level, seed)


def ratio_of_medians(ours, theirs, resamples=10000, level=0.90, seed=1):
    """median(ours) / median(theirs), with the same bootstrap interval. Where single samples have
    no finite variance (a tail index α ≤ 2, tail_index) a run's relMSE has no finite mean, and
    the ratio of means drifts with the largest run either side drew; the median of runs exists
    whatever the tail, and is what one run of each codebase most likely shows."""
    return bootstrap_ratio(ours, theirs, "median", resamples, level, seed)


def bootstrap_ratio(ours, theirs, statistic, resamples=10000, level=0.90, seed=1):
    """statistic(ours) / statistic(theirs) ("mean" or "median") and its percentile bootstrap interval."""
    import numpy as np
    f = {"mean": np.mean, "median": np.median}[statistic]
    a, b = np.asarray(ours, float), np.asarray(theirs, float)
    ratio = float(f(a) / f(b))
    rng = np.random.default_rng(seed)
    ra = f(a[rng.integers(0, a.size, (resamples, a.size))], axis=1)
    rb = f(b[rng.integers(0, b.size, (resamples, b.size))], axis=1)
    lo, hi = np.quantile(ra / rb, [(1 - level) / 2, (1 + level) / 2])
    return ratio, float(lo), float(hi)


def relmse(photonlab, image, reference):
    r = subprocess.run([photonlab, "compare", image, reference], check=True, capture_output=True, text=True)
    return json.loads(r.stdout.strip().splitlines()[-1])["relmse"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--smallvcm-src", required=True, help="a SmallVCM checkout (its src/ folder inside)")
    ap.add_argument("--photonlab", default=os.path.join(ROOT, "build", "photonlab"))
    ap.add_argument("--seconds", type=float, default=20.0, help="wall time per render")
    ap.add_argument("--reference-iterations", type=int, default=1024, help="photonlab's reference: vcm iterations")
    ap.add_argument("--reference-seconds", type=float, default=600.0, help="SmallVCM's reference: wall time")
    ap.add_argument("--repeats", type=int, default=1, help="runs of each method (relMSE averaged)")
    ap.add_argument("--first-run", type=int, default=0, metavar="K",
                    help="number of the first run: run k renders with photonlab seed k + 1 and SmallVCM seed "
                         "2000 + 100 k, so runs from K on are other samples than runs 0 to K - 1")
    ap.add_argument("--methods", default="", help="photonlab:smallvcm pairs, e.g. bdpt:bpt,vcm:vcm (default: all)")
    ap.add_argument("--scenes", default="sun,point")
    ap.add_argument("--photonlab-args", default="", metavar="ARGS",
                    help="more options for every photonlab run but the reference, e.g. \"--heuristic balance\"")
    ap.add_argument("--out", default="smallvcm-comparison")
    ap.add_argument("--tail", type=int, default=0, metavar="N",
                    help="count fireflies instead: N single-iteration renders per method (default methods bdpt:bpt)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    pairs = [tuple(p.split(":")) for p in a.methods.split(",")] if a.methods else PAIRS
    binary = build_smallvcm(a.smallvcm_src, a.out)
    if a.tail > 0:
        run_tail(a, binary, pairs if a.methods else [("bdpt", "bpt")])
        return
    rows, ratios = [], []
    for scene in a.scenes.split(","):
        ours_ref = os.path.join(a.out, "ref-photonlab-%s.exr" % scene)
        theirs_ref = os.path.join(a.out, "ref-smallvcm-%s.hdr" % scene)
        if not os.path.exists(ours_ref):
            # One pixel footprint at 512² (vcm's default is three: the reference would blur
            # its indirect light as much as vcm's own runs do).
            run_photonlab(a.photonlab, scene, "vcm", 0, ours_ref, seed=1000, spp=a.reference_iterations,
                          extra=["--radius", "0.00734"])
        if not os.path.exists(theirs_ref):
            run_smallvcm(binary, scene, "vcm", a.reference_seconds, theirs_ref)
        for ours, theirs in pairs:
            results = {}
            for k in range(a.first_run, a.first_run + a.repeats):
                if ours:
                    out = os.path.join(a.out, "photonlab-%s-%s-%d.exr" % (scene, ours, k))
                    wall, work = run_photonlab(a.photonlab, scene, ours, a.seconds, out, seed=k + 1,
                                               extra=shlex.split(a.photonlab_args))
                    results.setdefault(("photonlab", ours), []).append(
                        (wall, work, relmse(a.photonlab, out, ours_ref), trimmed_relmse(out, ours_ref)))
                if theirs:
                    out = os.path.join(a.out, "smallvcm-%s-%s-%d.hdr" % (scene, theirs, k))
                    wall, work = run_smallvcm(binary, scene, theirs, a.seconds, out, seed=2000 + 100 * k)
                    results.setdefault(("SmallVCM", theirs), []).append(
                        (wall, work, relmse(a.photonlab, out, theirs_ref), trimmed_relmse(out, theirs_ref)))
            if ("photonlab", ours) in results and ("SmallVCM", theirs) in results:
                mine, other = results[("photonlab", ours)], results[("SmallVCM", theirs)]
                r, lo, hi = ratio_of_means([x[2] for x in mine], [x[2] for x in other])
                rm, mlo, mhi = ratio_of_medians([x[2] for x in mine], [x[2] for x in other])
                ratios.append((scene, ours, theirs, len(mine), r, lo, hi, rm, mlo, mhi,
                               sum(x[3] for x in mine) / sum(x[3] for x in other)))
            for (code, method), runs in results.items():
                mean = sum(r[2] for r in runs) / len(runs)
                median = statistics.median(r[2] for r in runs)
                trimmed = sum(r[3] for r in runs) / len(runs)
                each = ", ".join("%s: %.4f (%.4f)" % (r[1].split()[0], r[2], r[3]) for r in runs)
                rows.append((scene, code, method, runs[-1][1], sum(r[0] for r in runs) / len(runs), mean, median, trimmed,
                             each))
                print("%-6s %-10s %-6s %-22s %6.1f s  relMSE %.5f (median %.5f)  best 99%% of pixels %.5f  runs %s"
                      % rows[-1], flush=True)
    table = ["| scene | code | method | work done (last run) | wall time | relMSE (mean) | median | best 99% of pixels | "
             "runs: iterations: relMSE (best 99%) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for scene, code, method, work, wall, err, median, trimmed, each in rows:
        table.append("| %s | %s | `%s` | %s | %.1f s | %.4f | %.4f | %.4f | %s |"
                     % (scene, code, method, work, wall, err, median, trimmed, each))
    if ratios:
        table += ["", "| scene | photonlab / SmallVCM | runs | ratio of means (90% bootstrap interval) | "
                      "ratio of medians (90% bootstrap interval) | ratio of best 99% of pixels |",
                  "|---|---|---|---|---|---|"]
        for scene, ours, theirs, n, r, lo, hi, rm, mlo, mhi, trimmed in ratios:
            table.append("| %s | `%s` / `%s` | %d | %.2f (%.2f–%.2f) | %.2f (%.2f–%.2f) | %.2f |"
                         % (scene, ours, theirs, n, r, lo, hi, rm, mlo, mhi, trimmed))
    text = "\n".join(table) + "\n"
    open(os.path.join(a.out, "table.md"), "w").write(text)
    print(text)


if __name__ == "__main__":
    main()
