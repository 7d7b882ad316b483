#!/usr/bin/python3
"""Convergence plots of an experiment: log–log relMSE and RMSE against render time and against
work (samples per pixel, or passes for the progressive methods), one line per run, the spread
over seeds as a band, and reference slopes −1 (unbiased Monte Carlo: MSE ∝ 1/N) and −2/3
(progressive photon mapping with α = 2/3: MSE ∝ N^(−2/3)).

    scripts/plot_convergence.py results/<name>/ [--out PREFIX]

Writes PREFIX.png and PREFIX.pdf (default results/<name>/convergence)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402


def curves(run, x_of, metric):
    """x (mean over seeds) and y (geometric mean, min, max over seeds) per checkpoint index."""
    by_index = {}
    for seq in run["seeds"].values():
        for r in seq:
            by_index.setdefault(int(r["checkpoint"]), []).append(r)
    xs, ys, lo, hi = [], [], [], []
    for _, group in sorted(by_index.items()):
        values = [r[metric] for r in group if r[metric] > 0]
        x = sum(x_of(r) for r in group) / len(group)
        if not values or x <= 0:
            continue
        xs.append(x)
        ys.append(er.geometric_mean(values))
        lo.append(min(values))
        hi.append(max(values))
    return xs, ys, lo, hi


def slope_guides(ax, xs_all, ys_all, metric):
    """Dashed lines of slope −1 and −2/3 through the median start point (MSE-type metrics; for
    RMSE the slopes halve)."""
    if not xs_all:
        return
    x0 = min(xs_all)
    x1 = max(xs_all)
    if x1 <= x0:
        return
    y0 = sorted(ys_all)[len(ys_all) // 2]
    scale = 0.5 if metric == "rmse" else 1.0
    for slope, style, name in [(-1.0, "--", "−1"), (-2.0 / 3.0, ":", "−2/3")]:
        s = slope * scale
        ax.plot([x0, x1], [y0, y0 * (x1 / x0) ** s], style, color="0.5", linewidth=1,
                label=f"slope {name}" + (" (MSE)" if metric == "rmse" else ""))


def plot(results_dir, out_prefix):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = er.read_metrics(results_dir)
    runs = er.runs(rows)
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), constrained_layout=True)
    for row_i, metric in enumerate(["relmse", "rmse"]):
        for col_i, (xname, x_of) in enumerate([("seconds", lambda r: r["seconds"]),
                                               ("samples per pixel / passes", er.work_of)]):
            ax = axes[row_i][col_i]
            xs_all, ys_all = [], []
            for i, (_, run) in enumerate(runs.items()):
                xs, ys, lo, hi = curves(run, x_of, metric)
                if not xs:
                    continue
                color = f"C{i % 10}"
                seeds = len(run["seeds"])
                label = f'{run["label"]} ({run["integrator"]}' + (f", {seeds} seeds)" if seeds > 1 else ")")
                ax.plot(xs, ys, "o-", color=color, markersize=3, label=label)
                if seeds > 1:
                    ax.fill_between(xs, lo, hi, color=color, alpha=0.2, linewidth=0)
                xs_all += xs
                ys_all += ys
            slope_guides(ax, xs_all, ys_all, metric)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xname)
            ax.set_ylabel("relMSE" if metric == "relmse" else "RMSE")
            ax.grid(True, which="both", alpha=0.3)
            if row_i == 0 and col_i == 0:
                ax.legend(fontsize=8)
    config_name = os.path.basename(os.path.normpath(results_dir))
    fig.suptitle(f"{config_name}: error against the reference")
    return er.save_figure(fig, out_prefix)


def main(argv=None):
    return er.figure_script_main("plot_convergence", __doc__, plot, "convergence", argv)


if __name__ == "__main__":
    sys.exit(main())
