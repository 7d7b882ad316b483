#!/usr/bin/python3
"""The report of an experiment: runs plot_convergence.py and compare_images.py, then writes
results/<name>/index.html, one page with the images, the plots and the table of final errors
(mean over seeds). The page uses relative links only, so it opens offline and moves with the
folder.

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


def png_of(results_dir, row):
    """The PNG beside a run's final EXR (final.png), if photonlab wrote one."""
    folder = os.path.dirname(row["png"]) if row["png"] else ""
    for name in ("final.png", "partial.png"):
        rel = os.path.join(folder, name)
        if folder and os.path.isfile(os.path.join(results_dir, rel)):
            return rel
    return None


def write_html(results_dir, config, table):
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
                 f"Revision <code>{e(prov.get('git_revision', 'unknown'))}</code> on {e(prov.get('cores', '?'))} cores. "
                 'Files: <a href="metrics.csv">metrics.csv</a>, <a href="experiment.toml">experiment.toml</a> '
                 "(the resolved config).</p>")
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
    return write_html(results_dir, config, final_table(rows))


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
