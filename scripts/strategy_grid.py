#!/usr/bin/python3
"""bdpt's techniques in one figure: the images `photonlab render ... --integrator bdpt --aov
strategies -o OUT.exr` writes beside OUT.exr (OUT.s<S>t<T>.exr), one row per depth k = s + t − 2,
one column per s, each tone-mapped as the PNGs are (clamp, sRGB), with the full image last.

    scripts/strategy_grid.py OUT.exr [--out FIGURE.png] [--exposure EV]
"""
import argparse
import glob
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("image")
    ap.add_argument("--out", default=None)
    ap.add_argument("--exposure", type=float, default=0.0)
    a = ap.parse_args()
    stem, ext = os.path.splitext(a.image)
    techniques = {}
    for path in glob.glob(glob.escape(stem) + ".s*t*" + ext):
        m = re.search(r"\.s(\d+)t(\d+)" + re.escape(ext) + "$", path)
        if m:
            techniques[(int(m.group(1)), int(m.group(2)))] = path
    if not techniques:
        sys.exit("strategy_grid: no %s.s<S>t<T>%s beside %s (render with --aov strategies)" % (stem, ext, a.image))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    depths = sorted({s + t - 2 for s, t in techniques})
    columns = max(depths) + 2
    fig, axes = plt.subplots(len(depths), columns + 1, figsize=(2.0 * (columns + 1), 2.1 * len(depths)), squeeze=False)

    def show(ax, path, title):
        ax.imshow(er.to_display(er.read_exr(path), a.exposure))
        ax.set_title(title, fontsize=9)

    for row, k in enumerate(depths):
        for col in range(columns + 1):
            ax = axes[row][col]
            ax.axis("off")
            if col <= k + 1 and (col, k + 2 - col) in techniques:
                show(ax, techniques[(col, k + 2 - col)], "depth %d: s=%d, t=%d" % (k, col, k + 2 - col))
        if row == 0:
            show(axes[0][columns], a.image, "full image")
    fig.tight_layout()
    out = a.out or stem + "-strategies.png"
    fig.savefig(out, dpi=80)
    print(out)


if __name__ == "__main__":
    main()
