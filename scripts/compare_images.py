#!/usr/bin/python3
"""Side-by-side comparison of an experiment: the reference and each run's final image (first
seed), a zoomed inset of the region `inset = [x, y, width, height]` given in the experiment
config, and false-colour maps of the per-pixel relative squared error (x − r)²/(r² + 0.01), on
one logarithmic colour scale shared by all runs.

    scripts/compare_images.py results/<name>/ [--out PREFIX]

Writes PREFIX.png and PREFIX.pdf (default results/<name>/comparison)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402


def panels(results_dir):
    """[(title, image path, row or None)]: the reference first, then one final image per run."""
    rows = er.read_metrics(results_dir)
    out = [("Reference", os.path.join(results_dir, "reference.exr"), None)]
    seen = set()
    for r in er.final_rows(rows):
        if int(r["run"]) in seen:
            continue  # first seed only
        seen.add(int(r["run"]))
        if "image" not in r or not r["image"]:
            raise er.ResultsError(f"{os.path.join(results_dir, 'metrics.csv')}: column image is empty for run {int(r['run'])}")
        title = f'{r["label"]}\n{r["seconds"]:.1f} s, relMSE {r["relmse"]:.3g}' + ("" if r["final"] else " (unfinished)")
        out.append((title, os.path.join(results_dir, r["image"]), r))
    return out


def plot(results_dir, out_prefix):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.patches as patches
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    config = er.read_config(results_dir)
    inset = config.get("inset")
    items = panels(results_dir)
    reference = er.read_exr(items[0][1])
    images = [er.read_exr(p) for _, p, _ in items]
    for (title, path, _), img in zip(items, images):
        if img.shape != reference.shape:
            raise er.ResultsError(f"{path}: {img.shape[1]}x{img.shape[0]}, the reference is "
                                  f"{reference.shape[1]}x{reference.shape[0]}")
    errors = [er.relmse_map(img, reference) for img in images[1:]]
    vmax = max([float(e.max()) for e in errors] + [1e-3])
    norm = LogNorm(vmin=max(vmax * 1e-4, 1e-6), vmax=vmax)

    n = len(items)
    nrows = 3 if inset else 2
    fig, axes = plt.subplots(nrows, n, figsize=(2.6 * n + 0.8, 2.7 * nrows), squeeze=False, constrained_layout=True)
    for col, ((title, _, _), img) in enumerate(zip(items, images)):
        ax = axes[0][col]
        ax.imshow(er.to_srgb(img), interpolation="nearest")
        ax.set_title(title, fontsize=8)
        if inset:
            x, y, w, h = inset
            ax.add_patch(patches.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor="yellow", linewidth=1))
            axes[1][col].imshow(er.to_srgb(img[y:y + h, x:x + w]), interpolation="nearest")
            axes[1][col].set_title("inset", fontsize=8)
    last = None
    for col in range(n):
        ax = axes[nrows - 1][col]
        if col == 0:
            ax.text(0.5, 0.5, "relative squared error\n(x − r)² / (r² + 0.01)", ha="center", va="center", fontsize=8)
        else:
            last = ax.imshow(errors[col - 1] + 1e-12, cmap="inferno", norm=norm, interpolation="nearest")
    for row in axes:
        for ax in row:
            ax.set_xticks([])
            ax.set_yticks([])
    if last is not None:
        fig.colorbar(last, ax=list(axes[nrows - 1]), shrink=0.9, label="relative squared error")
    fig.suptitle(f'{config.get("name", "")}: reference and runs')
    return er.save_figure(fig, out_prefix)


def main(argv=None):
    return er.figure_script_main("compare_images", __doc__, plot, "comparison", argv)


if __name__ == "__main__":
    sys.exit(main())
