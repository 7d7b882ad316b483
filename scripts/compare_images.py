#!/usr/bin/python3
"""Side-by-side comparison of an experiment, one column per image (the reference, then each
run's final image for its first seed), rows:
  1. the images, shown as the experiment's PNGs are (its `exposure` and `tonemap`);
  2. the zoomed inset `inset = [x, y, width, height]` (if the config gives one), with the ACES
     curve and an exposure lowered until the reference inset's brightest region (a caustic's
     core) is not clipped flat white; the same exposure for every column;
  3. the per-pixel relative squared error (x − r)²/(r² + 0.01), one logarithmic scale for all
     runs topped at their 99.9th percentile (its mean is the run's relMSE): where the error is;
  4. the signed relative difference (x − r)/(r + 0.1), a diverging scale symmetric about 0:
     bias shows as regions of one sign (too dark: blue, too bright: red), noise as speckle.

    scripts/compare_images.py results/<name>/ [--out PREFIX]

Writes PREFIX.png and PREFIX.pdf (default results/<name>/comparison)."""
import os
import sys

import numpy as np

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
    from matplotlib.colors import LogNorm, Normalize

    config = er.read_config(results_dir)
    exposure, tonemap = er.display_of(config)
    inset = config.get("inset")
    items = panels(results_dir)
    reference = er.read_exr(items[0][1])
    images = [er.read_exr(p) for _, p, _ in items]
    for (title, path, _), img in zip(items, images):
        if img.shape != reference.shape:
            raise er.ResultsError(f"{path}: {img.shape[1]}x{img.shape[0]}, the reference is "
                                  f"{reference.shape[1]}x{reference.shape[0]}")
    errors = [er.relmse_map(img, reference) for img in images[1:]]
    signed = [er.signed_difference_map(img, reference) for img in images[1:]]
    # One log scale for all runs, topped at the 99.9th percentile over all of them: a few
    # fireflies in one run would otherwise set the top and push every other map to black.
    vmax = max(float(np.percentile(np.concatenate([e.ravel() for e in errors]), 99.9)) if errors else 0.0, 1e-3)
    norm = LogNorm(vmin=max(vmax * 1e-4, 1e-6), vmax=vmax)
    # Symmetric limits: the 99th percentile of |difference| over all runs, between 5% and 100%.
    limit = float(np.clip(np.percentile(np.abs(np.concatenate([s.ravel() for s in signed])), 99), 0.05, 1.0)) if signed else 1.0
    signed_norm = Normalize(vmin=-limit, vmax=limit)
    if inset:
        x, y, w, h = inset
        inset_ev = er.inset_exposure(reference[y:y + h, x:x + w], exposure)

    n = len(items)
    rows = ["image"] + (["inset"] if inset else []) + ["relmse", "signed"]
    fig, axes = plt.subplots(len(rows), n, figsize=(2.6 * n + 1.2, 2.7 * len(rows)), squeeze=False, constrained_layout=True)
    last_err = last_signed = None
    for col, ((title, _, _), img) in enumerate(zip(items, images)):
        ax = axes[rows.index("image")][col]
        ax.imshow(er.to_display(img, exposure, tonemap), interpolation="nearest")
        ax.set_title(title, fontsize=8)
        if inset:
            ax.add_patch(patches.Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor="yellow", linewidth=1))
            axes[rows.index("inset")][col].imshow(er.to_display(img[y:y + h, x:x + w], inset_ev, "aces"), interpolation="nearest")
            axes[rows.index("inset")][col].set_title(f"inset (ACES, {inset_ev:+.1f} EV)", fontsize=8)
        for name, maps, cmap, nrm in [("relmse", errors, "inferno", norm), ("signed", signed, "RdBu_r", signed_norm)]:
            ax = axes[rows.index(name)][col]
            if col == 0:
                text = ("relative squared error\n(x − r)² / (r² + 0.01)\nlog scale; its mean is relMSE" if name == "relmse"
                        else "signed relative difference\n(x − r) / (r + 0.1)\nred: too bright, blue: too dark")
                ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=8)
                continue
            shown = ax.imshow(maps[col - 1] + (1e-12 if name == "relmse" else 0.0), cmap=cmap, norm=nrm, interpolation="nearest")
            if name == "relmse":
                last_err = shown
            else:
                last_signed = shown
    for row in axes:
        for ax in row:
            ax.set_xticks([])
            ax.set_yticks([])
    if last_err is not None:
        fig.colorbar(last_err, ax=list(axes[rows.index("relmse")]), shrink=0.9, label="relative squared error")
        fig.colorbar(last_signed, ax=list(axes[rows.index("signed")]), shrink=0.9, label="(x − r) / (r + 0.1)")
    display = f"exposure {exposure:+g} EV, {tonemap}"
    fig.suptitle(f'{config.get("name", "")}: reference and runs ({display}; first seed of each run)')
    return er.save_figure(fig, out_prefix)


def main(argv=None):
    return er.figure_script_main("compare_images", __doc__, plot, "comparison", argv)


if __name__ == "__main__":
    sys.exit(main())
