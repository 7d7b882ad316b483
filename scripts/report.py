#!/usr/bin/python3
"""The report of an experiment: runs plot_convergence.py and compare_images.py, then writes
results/<name>/index.html, one page with
  - the reference: its integrator, settings, seed, render time and revision;
  - a summary: each run's relMSE at equal time (the shortest run's time), its time to reach a
    target relMSE (the config's `target_relmse`, or the baseline's final relMSE), and its
    speed-up over the baseline run (the config's `baseline`, or the first run) at that target,
    all read off the convergence curves by log–log interpolation;
  - the table of final errors (mean over seeds), the images and the figures;
  - the machine (CPU model, cores) and the photonlab revision that rendered it.
The page uses relative links only, so it opens offline and moves with the folder.

    scripts/report.py results/<name>/"""
import argparse
import html
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_images  # noqa: E402
import experiment_results as er  # noqa: E402
import plot_convergence  # noqa: E402


def final_table(rows):
    """One line per run: mean (and spread) over seeds of the final row's numbers."""
    table = []
    for run, info in er.runs(rows).items():
        finals = [seq[-1] for seq in info["seeds"].values()]
        relmse = [r["relmse"] for r in finals]
        table.append({
            "run": run,
            "label": info["label"],
            "integrator": info["integrator"],
            "seeds": len(finals),
            "finished": all(r["final"] for r in finals),
            "seconds": statistics.fmean(r["seconds"] for r in finals),
            "work": statistics.fmean(er.work_of(r) for r in finals),
            "work_unit": "passes" if info["integrator"] in er.PROGRESSIVE else "spp",
            "relmse": statistics.fmean(relmse),
            "relmse_sd": statistics.stdev(relmse) if len(relmse) > 1 else 0.0,
            "rmse": statistics.fmean(r["rmse"] for r in finals),
            "mae": statistics.fmean(r["mae"] for r in finals),
            "mean_ratio": statistics.fmean(float(r["mean_ratio"]) for r in finals) if "mean_ratio" in finals[0] else float("nan"),
            "png": os.path.splitext(finals[0]["image"])[0] if finals[0].get("image") else "",
        })
    return table


def summary_table(rows, config):
    """Equal time, time to a target error, and speed-up over a baseline, one line per run.

    Curves are each run's geometric mean of relMSE over seeds against the mean time over seeds
    (plot_convergence's lines). Equal time is the shortest run's final time; the target is
    `target_relmse`, or else the baseline's final relMSE: "how long does each method take to
    reach the baseline's quality". Speed-up = baseline's time to the target / the run's."""
    runs = er.runs(rows)
    curves = {i: er.mean_curve(run, lambda r: r["seconds"], "relmse") for i, run in runs.items()}
    curves = {i: c for i, c in curves.items() if c[0]}
    if not curves:
        return [], None, None, None
    equal_time = min(c[0][-1] for c in curves.values())
    baseline_label = config.get("baseline") or runs[min(runs)]["label"]
    baseline = next((i for i, run in runs.items() if run["label"] == baseline_label), min(runs))
    if baseline not in curves:
        baseline = min(curves)
    target = float(config.get("target_relmse", 0) or 0) or curves[baseline][1][-1]
    times = {i: er.loglog_time_to(c[0], c[1], target) for i, c in curves.items()}
    out = []
    for i, (xs, ys, _, _) in curves.items():
        t = times[i]
        b = times.get(baseline)
        out.append({"run": i, "label": runs[i]["label"], "integrator": runs[i]["integrator"],
                    "relmse_at_equal_time": er.loglog_at(xs, ys, equal_time),
                    "time_to_target": t,
                    "speedup": (b / t) if (t and b) else None,
                    "baseline": i == baseline})
    return out, equal_time, target, baseline_label


def reference_info(results_dir, config):
    """What the reference is: from reference.exr's metadata (what photonlab recorded when it
    rendered it) and the resolved config's [reference] table."""
    meta = er.read_image_metadata(os.path.join(results_dir, "reference.exr"))
    settings = dict(config.get("reference", {}))
    return meta, settings


def png_of(results_dir, row):
    """The PNG beside a run's final EXR (final.png), if photonlab wrote one."""
    folder = os.path.dirname(row["png"]) if row["png"] else ""
    for name in ("final.png", "partial.png"):
        rel = os.path.join(folder, name)
        if folder and os.path.isfile(os.path.join(results_dir, rel)):
            return rel
    return None


def fmt(v, spec):
    return "—" if v is None else format(v, spec)


def write_html(results_dir, config, table, summary=None, reference=None):
    e = html.escape
    name = config.get("name", os.path.basename(os.path.normpath(results_dir)))
    prov = config.get("provenance", {})
    lines = [
        "<!doctype html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{e(name)} — photonlab</title>",
        "<style>body{font-family:sans-serif;margin:2em;max-width:1400px}"
        "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}"
        "td:first-child,th:first-child{text-align:left}figure{display:inline-block;margin:0 1em 1em 0;vertical-align:top}"
        "figure img{image-rendering:pixelated;width:256px;border:1px solid #888}figcaption{font-size:90%;max-width:256px}"
        ".plot{max-width:100%;border:1px solid #ddd}</style></head><body>",
        f"<h1>{e(name)}</h1>",
    ]
    if config.get("description"):
        lines.append(f"<p>{e(config['description'])}</p>")
    lines.append(f"<p>Scene <code>{e(str(config.get('scene', '')))}</code>, {config.get('width')}×{config.get('height')} pixels. "
                 f"Rendered by photonlab <code>{e(prov.get('git_revision', 'unknown'))}</code> on "
                 f"{e(prov.get('cpu', 'an unknown CPU'))}, {e(prov.get('cores', '?'))} cores. "
                 'Files: <a href="metrics.csv">metrics.csv</a>, <a href="experiment.toml">experiment.toml</a> '
                 "(the resolved config).</p>")
    if reference is not None:
        meta, settings = reference
        lines.append("<h2>Reference</h2>")
        if "reference_file" in meta or "file" in settings:
            lines.append(f"<p>An image given by the config: <code>{e(str(settings.get('file', meta.get('reference_file', ''))))}</code>.</p>")
        else:
            keys = ", ".join(f"{k} = {er.readable_number(v)}" for k, v in settings.items() if k not in ("integrator", "seed"))
            work = (f"{meta['passes']} passes of {meta.get('photons_per_pass', '?')} photon paths" if "passes" in meta
                    else f"{meta.get('spp', '?')} spp")
            seconds = float(meta["seconds"]) if "seconds" in meta else None
            lines.append(f"<p>Integrator <b>{e(meta.get('integrator', str(settings.get('integrator', '?'))))}</b> ({e(keys)}), "
                         f"seed {e(meta.get('seed', str(settings.get('seed', '?'))))} (its own stream: no run draws from it), "
                         f"{e(work)}, rendered in {fmt(seconds, '.1f')} s"
                         + (f" by photonlab <code>{e(meta['git_revision'])}</code>" if "git_revision" in meta else "")
                         + ". A reference is only as good as its own convergence: compare its cost with the runs'.</p>")
    if summary is not None and summary[0]:
        rows, equal_time, target, baseline = summary
        lines.append("<h2>Summary</h2><table><tr><th>run</th><th>integrator</th>"
                     f"<th>relMSE at {equal_time:.3g} s (equal time)</th>"
                     f"<th>time to relMSE {target:.3g} (s)</th><th>speed-up over {e(baseline)}</th></tr>")
        for r in rows:
            speed = "1 (baseline)" if r["baseline"] else (fmt(r["speedup"], ".3g") + "×" if r["speedup"] else "—")
            lines.append(f"<tr><td>{e(r['label'])}</td><td>{e(r['integrator'])}</td>"
                         f"<td>{fmt(r['relmse_at_equal_time'], '.4g')}</td><td>{fmt(r['time_to_target'], '.3g')}</td>"
                         f"<td>{speed}</td></tr>")
        lines.append("</table><p>Read off each run's convergence curve (geometric mean of relMSE over seeds against "
                     "render time) by log–log interpolation between checkpoints. Equal time: the shortest run's final "
                     "time. Target: " + ("the config's <code>target_relmse</code>" if config.get("target_relmse")
                                        else "the baseline's final relMSE") +
                     ". Speed-up: the baseline's time to the target over the run's; — where a curve never reaches it "
                     "(an error that levels off, e.g. a path tracer missing a caustic).</p>")
    lines.append("<h2>Final errors</h2><table><tr><th>run</th><th>integrator</th><th>seeds</th><th>seconds</th>"
                 "<th>spp / passes</th><th>relMSE</th><th>RMSE</th><th>MAE</th><th>mean ratio</th></tr>")
    for t in table:
        sd = f" ± {t['relmse_sd']:.2g}" if t["seeds"] > 1 else ""
        flag = "" if t["finished"] else " (unfinished)"
        lines.append(f"<tr><td>{e(t['label'])}{flag}</td><td>{e(t['integrator'])}</td><td>{t['seeds']}</td>"
                     f"<td>{t['seconds']:.2f}</td><td>{t['work']:.0f} {t['work_unit']}</td><td>{t['relmse']:.4g}{sd}</td>"
                     f"<td>{t['rmse']:.4g}</td><td>{t['mae']:.4g}</td><td>{t['mean_ratio']:.4f}</td></tr>")
    lines.append("</table><p>relMSE = mean of (x − r)²/(r² + 0.01) over pixels and channels; mean ratio = "
                 "mean(x)/mean(r) (1: no overall bias). Values are means over seeds (± standard deviation).</p>")
    lines.append("<h2>Images</h2>")
    lines.append('<figure><img src="reference.png" alt="reference"><figcaption>Reference</figcaption></figure>')
    for t in table:
        png = png_of(results_dir, t)
        if png:
            lines.append(f'<figure><img src="{e(png)}" alt="{e(t["label"])}"><figcaption>{e(t["label"])}: '
                         f'{t["seconds"]:.1f} s, relMSE {t["relmse"]:.3g}</figcaption></figure>')
    lines.append("<h2>Convergence</h2>")
    lines.append('<p><img class="plot" src="convergence.png" alt="convergence plot"> '
                 '(<a href="convergence.pdf">PDF</a>)</p>')
    lines.append("<h2>Comparison</h2>")
    lines.append('<p><img class="plot" src="comparison.png" alt="image comparison"> '
                 '(<a href="comparison.pdf">PDF</a>)</p>')
    lines.append("</body></html>")
    path = os.path.join(results_dir, "index.html")
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(path + ".tmp", path)
    return path


def report(results_dir):
    rows = er.read_metrics(results_dir)
    config = er.read_config(results_dir)
    plot_convergence.plot(results_dir, os.path.join(results_dir, "convergence"))
    compare_images.plot(results_dir, os.path.join(results_dir, "comparison"))
    return write_html(results_dir, config, final_table(rows), summary_table(rows, config),
                      reference_info(results_dir, config))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("results_dir")
    a = p.parse_args(argv)
    try:
        path = report(a.results_dir)
    except er.ResultsError as e:
        print(f"report: {e}", file=sys.stderr)
        return 2
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
