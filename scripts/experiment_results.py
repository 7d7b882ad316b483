"""Reading what `photonlab run` writes into results/<name>/: metrics.csv, experiment.toml and
the EXR images. Shared by plot_convergence.py, compare_images.py and report.py.

Bad input raises ResultsError with a one-line message naming the file; the scripts print it and
exit with status 2 instead of showing a traceback."""
import argparse
import csv
import math
import os
import sys
import tomllib

import numpy as np

# The documented columns of metrics.csv (photonlab may add more after them).
REQUIRED_COLUMNS = ["run", "label", "integrator", "seed", "checkpoint", "seconds", "spp", "passes",
                    "photons", "rmse", "relmse", "mae"]
NUMERIC_COLUMNS = ["run", "seed", "checkpoint", "seconds", "spp", "passes", "photons", "rmse", "relmse", "mae"]
PROGRESSIVE = {"ppm", "sppm", "pppm"}


class ResultsError(Exception):
    pass


def read_metrics(results_dir):
    """Rows of metrics.csv as dicts, numeric columns converted; checks the header first."""
    path = os.path.join(results_dir, "metrics.csv")
    if not os.path.isfile(path):
        raise ResultsError(f"{path}: no such file (is {results_dir} a results folder of `photonlab run`?)")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        header = reader.fieldnames or []
        missing = [c for c in REQUIRED_COLUMNS if c not in header]
        if missing:
            raise ResultsError(f"{path}: missing column(s) {', '.join(missing)} (header: {','.join(header)})")
        rows = []
        for line, row in enumerate(reader, start=2):
            for c in NUMERIC_COLUMNS:
                try:
                    row[c] = float(row[c])
                except (TypeError, ValueError):
                    raise ResultsError(f"{path}:{line}: column {c}: not a number: {row[c]!r}") from None
            row["final"] = row.get("final", "0") == "1"
            rows.append(row)
    if not rows:
        raise ResultsError(f"{path}: no rows yet (has the experiment rendered anything?)")
    return rows


def read_config(results_dir):
    """The resolved experiment.toml photonlab wrote (every default filled in)."""
    path = os.path.join(results_dir, "experiment.toml")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise ResultsError(f"{path}: no such file") from None
    except tomllib.TOMLDecodeError as e:
        raise ResultsError(f"{path}: {e}") from None


def read_exr(path):
    """Linear RGB float image (H, W, 3)."""
    import OpenImageIO as oiio  # Debian's python3-openimageio
    if not os.path.isfile(path):
        raise ResultsError(f"{path}: no such image")
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        raise ResultsError(f"{path}: {buf.geterror()}")
    pixels = buf.get_pixels(oiio.FLOAT)
    if pixels is None or pixels.ndim != 3 or pixels.shape[2] < 3:
        raise ResultsError(f"{path}: not an RGB image")
    return np.asarray(pixels[:, :, :3], dtype=np.float64)


def to_srgb(linear):
    """Display transform photonlab's PNGs use: clamp to [0, 1], then the sRGB curve."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def relmse_map(image, reference):
    """Per-pixel relative squared error, averaged over channels: (x − r)² / (r² + 0.01), the same
    definition as photonlab's relmse (so its mean over pixels is the relmse column)."""
    return np.mean((image - reference) ** 2 / (reference ** 2 + 0.01), axis=2)


def runs(rows):
    """{run index: {"label", "integrator", "seeds": {seed: [rows in checkpoint order]}}}."""
    out = {}
    for r in rows:
        run = out.setdefault(int(r["run"]), {"label": r["label"], "integrator": r["integrator"], "seeds": {}})
        run["seeds"].setdefault(int(r["seed"]), []).append(r)
    for run in out.values():
        for seq in run["seeds"].values():
            seq.sort(key=lambda r: r["checkpoint"])
    return dict(sorted(out.items()))


def work_of(row):
    """Samples per pixel, or passes for the progressive methods: the x axis of equal-work plots."""
    return row["passes"] if row["integrator"] in PROGRESSIVE else row["spp"]


def final_rows(rows):
    """The last row of every (run, seed): the final image, or the latest checkpoint of an unfinished run."""
    last = {}
    for r in rows:
        key = (int(r["run"]), int(r["seed"]))
        if key not in last or r["checkpoint"] > last[key]["checkpoint"]:
            last[key] = r
    return [last[k] for k in sorted(last)]


def geometric_mean(values):
    values = [v for v in values if v > 0 and math.isfinite(v)]
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else float("nan")


def save_figure(fig, out_prefix):
    """PNG and PDF of a matplotlib figure, each written to a temporary file and renamed into
    place (never half-written); closes the figure. Returns the two paths."""
    import matplotlib.pyplot as plt
    written = []
    for ext in ("png", "pdf"):
        fig.savefig(f"{out_prefix}.{ext}.tmp", format=ext, dpi=110)
        os.replace(f"{out_prefix}.{ext}.tmp", f"{out_prefix}.{ext}")
        written.append(f"{out_prefix}.{ext}")
    plt.close(fig)
    return written


def figure_script_main(name, doc, plot, default_stem, argv=None):
    """The command line of a figure script: `NAME RESULTS_DIR [--out PREFIX]`, errors as one line
    on stderr and exit status 2, the written paths on stdout."""
    p = argparse.ArgumentParser(prog=name, description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("results_dir")
    p.add_argument("--out", help=f"output prefix (default RESULTS_DIR/{default_stem})")
    a = p.parse_args(argv)
    try:
        written = plot(a.results_dir, a.out or os.path.join(a.results_dir, default_stem))
    except ResultsError as e:
        print(f"{name}: {e}", file=sys.stderr)
        return 2
    for w in written:
        print(w)
    return 0
