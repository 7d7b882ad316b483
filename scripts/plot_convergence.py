#!/usr/bin/python3
"""Convergence plots of an experiment, one line per run (geometric mean over seeds, the min–max
range over seeds as a band):
  - relMSE and RMSE against render time and against work (samples per pixel, or photon passes
    for the progressive methods), log–log;
  - the mean ratio mean(x)/mean(r) against the same axes: 1 means no overall brightening or
    darkening, so a bias shows here even where noise hides it in the errors.
Each curve has slope guides anchored at its last point: MSE slopes −1 (unbiased Monte Carlo,
MSE ∝ 1/N) and −2/3 (progressive photon mapping with α = 2/3); for RMSE they halve to −1/2 and
−1/3. Every panel has its legend; the figure's caption says what the x axes count.

    scripts/plot_convergence.py results/<name>/ [--out PREFIX]

Writes PREFIX.png and PREFIX.pdf (default results/<name>/convergence)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import experiment_results as er  # noqa: E402


def curves(run, x_of, metric):
    """x (mean over seeds) and y (geometric mean, min, max over seeds) per checkpoint index."""
    return er.mean_curve(run, x_of, metric)


# (MSE slope, line style, label) of the guides; RMSE slopes are half of these.
GUIDES = [(-1.0, (0, (4, 2)), "−1"), (-2.0 / 3.0, (0, (1, 1.5)), "−2/3")]


def slope_guides(ax, xs, ys, metric, color):
    """Short guides through the curve's last point, back one decade (or to its first x): where
    the curve's tail runs parallel to one, it converges at that rate."""
    if len(xs) < 2 or xs[-1] <= xs[0]:
        return
    x1, y1 = xs[-1], ys[-1]
    x0 = max(xs[0], x1 / 10)
    scale = 0.5 if metric == "rmse" else 1.0
    for slope, style, _ in GUIDES:
        s = slope * scale
        ax.plot([x0, x1], [y1 * (x0 / x1) ** s, y1], linestyle=style, color=color, linewidth=0.9, alpha=0.7)


def guide_legend_handles(metric):
    from matplotlib.lines import Line2D
    scale = 0.5 if metric == "rmse" else 1.0
    names = {"−1": "−1/2", "−2/3": "−1/3"} if metric == "rmse" else {}
    return [Line2D([], [], linestyle=style, color="0.4", linewidth=0.9,
                   label=f"slope {names.get(name, name)} through the last point" +
                         (" (unbiased)" if slope == -1.0 else " (PPM family, α = 2/3)"))
            for slope, style, name in GUIDES]


X_AXES = [("render time (s)", lambda r: r["seconds"]),
          ("samples per pixel, or photon passes", er.work_of)]


def plot(results_dir, out_prefix):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = er.read_metrics(results_dir)
    runs = er.runs(rows)
    has_ratio = all("mean_ratio" in r and r["mean_ratio"] not in ("", None) for r in rows)
    metrics = ["relmse", "rmse"] + (["mean_ratio"] if has_ratio else [])
    if has_ratio:
        for r in rows:
            r["mean_ratio"] = float(r["mean_ratio"])
    fig, axes = plt.subplots(len(metrics), 2, figsize=(12, 4.2 * len(metrics)), constrained_layout=True, squeeze=False)
    for row_i, metric in enumerate(metrics):
        for col_i, (xname, x_of) in enumerate(X_AXES):
            ax = axes[row_i][col_i]
            for i, (_, run) in enumerate(runs.items()):
                color = f"C{i % 10}"
                seeds = len(run["seeds"])
                label = f'{run["label"]} ({run["integrator"]}' + (f", {seeds} seeds)" if seeds > 1 else ")")
                # Errors: geometric mean over seeds; the mean ratio: arithmetic. The range as a band.
                xs, ys, lo, hi = er.mean_curve(run, x_of, metric, geometric=metric != "mean_ratio")
                if not xs:
                    continue
                ax.plot(xs, ys, "o-", color=color, markersize=3, label=label)
                if seeds > 1:
                    ax.fill_between(xs, lo, hi, color=color, alpha=0.2, linewidth=0)
                if metric != "mean_ratio":
                    slope_guides(ax, xs, ys, metric, color)
            ax.set_xscale("log")
            if metric == "mean_ratio":
                ax.axhline(1.0, color="0.3", linewidth=0.8)
                ax.set_ylabel("mean ratio  mean(x) / mean(r)")
            else:
                ax.set_yscale("log")
                ax.set_ylabel("relMSE" if metric == "relmse" else "RMSE")
            ax.set_xlabel(xname)
            ax.grid(True, which="both", alpha=0.3)
            er.readable_log_axis(ax.xaxis)
            if metric != "mean_ratio":
                er.readable_log_axis(ax.yaxis)
            handles, _ = ax.get_legend_handles_labels()
            if metric != "mean_ratio":
                handles += guide_legend_handles(metric)
            ax.legend(handles=handles, fontsize=9, loc="best")
    try:
        config_name = er.read_config(results_dir).get("name") or os.path.basename(os.path.normpath(results_dir))
    except er.ResultsError:
        config_name = os.path.basename(os.path.normpath(results_dir))
    fig.suptitle(f"{config_name}: error against the reference")
    fig.text(0.5, -0.01,
             "Left: render time in seconds (image writes and error computation excluded). Right: samples per pixel "
             "(direct, whitted, path, photon) or photon passes (ppm, sppm, pppm). Lines: geometric mean over seeds; "
             "bands: min–max over seeds. relMSE = mean (x − r)²/(r² + 0.01).",
             ha="center", va="top", fontsize=9, wrap=True)
    return er.save_figure(fig, out_prefix)


def main(argv=None):
    return er.figure_script_main("plot_convergence", __doc__, plot, "convergence", argv)


if __name__ == "__main__":
    sys.exit(main())
