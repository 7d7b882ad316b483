#!/usr/bin/python3
"""Do two photonlab builds converge to the same image? For an estimator change (one that alters
bits, so scripts/compare_builds.sh cannot prove it): renders a scene with each build over many
seeds, interleaved (old, new, old, ...), and compares them region by region. Each image is cut
into TILES x TILES regions; a region's value is its mean radiance, and across seeds each build
gives a mean and a standard error for it. Where both builds estimate the same image, the
difference of the two means over its standard error, z, is close to standard normal in every
region and for the whole image's mean: |z| > 4 happens in fewer than 1 in 15,000 by chance.

    scripts/compare_convergence.py OLD NEW SCENE --integrator ppm [--seeds 16] [--tiles 8]
        [--markdown FILE] [-- extra render options, e.g. --passes 16 --width 64]

Prints one line per integrator; exits 1 if any region has |z| > 4 (or either build failed)."""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402

Z_LIMIT = 4.0


def render(binary, scene, integrator, seed, extra, out):
    cmd = [binary, "render", scene, "--integrator", integrator, "--seed", str(seed), "-q", "-o", out] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return er.read_exr(out)


def tile_means(image, tiles):
    """(tiles, tiles) mean of the channel average over each region."""
    h, w, _ = image.shape
    lum = image.mean(axis=2)
    ys = np.linspace(0, h, tiles + 1).astype(int)
    xs = np.linspace(0, w, tiles + 1).astype(int)
    return np.array([[lum[ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean() for j in range(tiles)] for i in range(tiles)])


def compare(old, new, scene, integrator, seeds, tiles, extra):
    a, b = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for s in range(1, seeds + 1):  # interleaved: a load change on the machine hits both alike
            a.append(tile_means(render(old, scene, integrator, s, extra, os.path.join(tmp, "a.exr")), tiles))
            b.append(tile_means(render(new, scene, integrator, s, extra, os.path.join(tmp, "b.exr")), tiles))
    a, b = np.array(a), np.array(b)
    ma, mb = a.mean(axis=0), b.mean(axis=0)
    se = np.sqrt(a.var(axis=0, ddof=1) / seeds + b.var(axis=0, ddof=1) / seeds)
    # A region both builds render exactly alike in every seed (black, or a constant) has se = 0.
    exact = se == 0
    z = np.where(exact, 0.0, (mb - ma) / np.where(exact, 1.0, se))
    # The whole image's mean likewise, over the seeds' image means.
    ia, ib = a.mean(axis=(1, 2)), b.mean(axis=(1, 2))
    image_se = np.sqrt(ia.var(ddof=1) / seeds + ib.var(ddof=1) / seeds)
    return {
        "image_z": float((ib.mean() - ia.mean()) / image_se) if image_se > 0 else 0.0,
        "integrator": integrator,
        "regions": tiles * tiles,
        "max_z": float(np.abs(z).max()),
        "over_3": int((np.abs(z) > 3).sum()),
        "mean_old": float(ma.mean()),
        "mean_new": float(mb.mean()),
        "relative_difference": float((mb.mean() - ma.mean()) / ma.mean()) if ma.mean() else 0.0,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("scene")
    ap.add_argument("--integrator", action="append", required=True, help="repeat for several")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--tiles", type=int, default=8)
    ap.add_argument("--markdown", help="also write the table to this file")
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []  # render options after --
    args = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    args.extra = extra
    if args.seeds < 2:
        sys.exit("compare_convergence.py: --seeds: at least 2 (a standard error needs two)")
    rows, failed = [], False
    for integrator in args.integrator:
        try:
            r = compare(args.old, args.new, args.scene, integrator, args.seeds, args.tiles, args.extra)
        except subprocess.CalledProcessError as e:
            print(f"{integrator}: render failed: {e.stderr.decode().strip()}", file=sys.stderr)
            failed = True
            continue
        rows.append(r)
        ok = r["max_z"] <= Z_LIMIT and abs(r["image_z"]) <= Z_LIMIT
        failed |= not ok
        print(f'{integrator}: {r["regions"]} regions, max |z| {r["max_z"]:.2f}, {r["over_3"]} over 3; image mean '
              f'{r["mean_old"]:.5g} -> {r["mean_new"]:.5g} ({100 * r["relative_difference"]:+.2f}%, z {r["image_z"]:+.2f}): '
              f'{"agree" if ok else "DIFFER"}')
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write("| integrator | regions | max \\|z\\| | \\|z\\| > 3 | image mean, old | new | difference | its z |\n")
            f.write("|---|---:|---:|---:|---:|---:|---:|---:|\n")
            for r in rows:
                f.write(f'| {r["integrator"]} | {r["regions"]} | {r["max_z"]:.2f} | {r["over_3"]} | {r["mean_old"]:.5g} | '
                        f'{r["mean_new"]:.5g} | {100 * r["relative_difference"]:+.2f}% | {r["image_z"]:+.2f} |\n')
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
