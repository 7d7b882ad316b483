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
    """Linear RGB float image (H, W, 3), from an EXR (or any format OpenImageIO reads: HDR)."""
    import OpenImageIO as oiio  # Debian's python3-openimageio
    if not os.path.isfile(path):
        raise ResultsError(f"{path}: no such image")
    # ImageInput, not ImageBuf: ImageBuf reads through OpenImageIO's shared image cache, which
    # returns a file's old pixels when it was rewritten within the same second (a script that
    # renders to one name again and again read a stale image 6 times in 10).
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise ResultsError(f"{path}: {oiio.geterror()}")
    pixels = inp.read_image(oiio.FLOAT)
    inp.close()
    if pixels is None or pixels.ndim != 3 or pixels.shape[2] < 3:
        raise ResultsError(f"{path}: not an RGB image")
    return np.asarray(pixels[:, :, :3], dtype=np.float64)


def aces_filmic(x):
    """Narkowicz's fit of the ACES filmic curve, as photonlab's PNGs use it (src/image/tonemap.h):
    highlights roll off (f(1) = 0.80, f(4) = 0.97) instead of clipping; white from x ≈ 7.2."""
    x = np.maximum(x, 0.0)
    return np.minimum(1.0, x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14))


def to_display(linear, exposure=0.0, tonemap="clamp"):
    """Linear radiance to display values in [0, 1], as photonlab's PNGs: × 2^exposure, the tone
    curve ("clamp" or "aces"), then the sRGB transfer curve."""
    x = np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0) * 2.0 ** exposure
    x = aces_filmic(x) if tonemap == "aces" else np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def to_srgb(linear):
    """photonlab's default PNG transform: clamp to [0, 1], then the sRGB curve."""
    return to_display(linear)


def display_of(config):
    """(exposure, tonemap) of an experiment's resolved config (defaults 0 and "clamp")."""
    return float(config.get("exposure", 0.0)), str(config.get("tonemap", "clamp"))


def luminance(rgb):
    """Rec. 709 / sRGB luminance of linear RGB."""
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def inset_exposure(reference_inset, exposure):
    """Exposure for a zoomed inset shown with the ACES curve: the experiment's, lowered when needed
    so that the reference inset's 99.9th-percentile luminance lands at 4 (display 0.97), so that
    its brightest region, a caustic's core, keeps its shape instead of clipping flat white."""
    peak = float(np.percentile(luminance(reference_inset), 99.9)) if reference_inset.size else 0.0
    if not (peak > 0 and math.isfinite(peak)):
        return exposure
    return min(exposure, math.log2(4.0 / peak))


def relmse_map(image, reference):
    """Per-pixel relative squared error, averaged over channels: (x − r)² / (r² + 0.01), the same
    definition as photonlab's relmse (so its mean over pixels is the relmse column)."""
    return np.mean((image - reference) ** 2 / (reference ** 2 + 0.01), axis=2)


# ε of the signed relative difference: √0.01, so that where r ≫ ε its square is the relMSE term.
SIGNED_EPSILON = 0.1


def signed_difference_map(image, reference):
    """Per-pixel signed relative difference, averaged over channels: (x − r) / (r + ε). Bias shows
    as coherent regions of one sign (blur: a bright edge too dark and its neighbour too bright;
    darkening: blue everywhere), noise as speckle of both signs."""
    return np.mean((image - reference) / (reference + SIGNED_EPSILON), axis=2)


def loglog_at(xs, ys, x):
    """y at x on the piecewise-linear log–log curve through (xs, ys) (xs increasing); None outside."""
    pts = [(a, b) for a, b in zip(xs, ys) if a > 0 and b > 0]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x0 <= x <= x1:
            if x1 == x0:
                return y0
            t = (math.log(x) - math.log(x0)) / (math.log(x1) - math.log(x0))
            return math.exp(math.log(y0) + t * (math.log(y1) - math.log(y0)))
    if pts and x == pts[-1][0]:
        return pts[-1][1]
    return None


def loglog_time_to(xs, ys, target):
    """The first x at which the log–log curve through (xs, ys) reaches y = target (interpolated);
    xs[0] if it starts below, None if it never gets there."""
    pts = [(a, b) for a, b in zip(xs, ys) if a > 0 and b > 0]
    if not pts:
        return None
    if pts[0][1] <= target:
        return pts[0][0]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if y1 <= target < y0:
            t = (math.log(target) - math.log(y0)) / (math.log(y1) - math.log(y0))
            return math.exp(math.log(x0) + t * (math.log(x1) - math.log(x0)))
    return None


def mean_curve(run, x_of, metric, geometric=True):
    """A run's curve over its checkpoints, one point per checkpoint index: x the mean over seeds,
    y the geometric mean over seeds (errors; zeros skipped) or the arithmetic one (the mean
    ratio), and the min and max."""
    by_index = {}
    for seq in run["seeds"].values():
        for r in seq:
            by_index.setdefault(int(r["checkpoint"]), []).append(r)
    xs, ys, lo, hi = [], [], [], []
    for _, group in sorted(by_index.items()):
        values = [float(r[metric]) for r in group if not geometric or r[metric] > 0]
        x = sum(x_of(r) for r in group) / len(group)
        if not values or x <= 0:
            continue
        xs.append(x)
        ys.append(geometric_mean(values) if geometric else sum(values) / len(values))
        lo.append(min(values))
        hi.append(max(values))
    return xs, ys, lo, hi


def read_image_metadata(path):
    """photonlab's metadata attributes of an image (the "photonlab:" prefix removed), as strings."""
    import OpenImageIO as oiio
    if not os.path.isfile(path):
        return {}
    inp = oiio.ImageInput.open(path)  # uncached, as read_exr
    if inp is None:
        return {}
    spec = inp.spec()
    inp.close()
    return {a.name[len("photonlab:"):]: str(a.value) for a in spec.extra_attribs if a.name.startswith("photonlab:")}


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


def readable_number(v):
    """A value as a reader wants it in a report: 4 significant digits for a real number
    (0.6666666666666666 reads 0.6667), integers and text as they are."""
    if isinstance(v, bool) or not isinstance(v, float):
        return str(v)
    return f"{v:.4g}"


def readable_log_axis(axis):
    """Labels on a log axis wherever the data's range has room for them: matplotlib labels only
    the powers of ten, and a range within one or two decades (an RMSE falling from 0.03 to 0.008)
    then shows one labelled tick or none. Below three decades the ticks go to 1, 2 and 5 times
    the powers of ten (within one decade to 1, 1.5, 2, 3, 5 and 7 times), each labelled in plain
    numbers; wider ranges keep the powers of ten."""
    from matplotlib import ticker
    lo, hi = sorted(axis.get_view_interval())
    if not (lo > 0 and hi > lo) or math.log10(hi / lo) >= 3:
        return
    subs = (1.0, 1.5, 2.0, 3.0, 5.0, 7.0) if math.log10(hi / lo) < 1 else (1.0, 2.0, 5.0)
    axis.set_major_locator(ticker.LogLocator(base=10, subs=subs))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:.3g}"))
    axis.set_minor_formatter(ticker.NullFormatter())


def save_figure(fig, out_prefix):
    """PNG and PDF of a matplotlib figure, each written to a temporary file and renamed into
    place (never half-written); closes the figure. Returns the two paths."""
    import matplotlib.pyplot as plt
    written = []
    for ext in ("png", "pdf"):
        fig.savefig(f"{out_prefix}.{ext}.tmp", format=ext, dpi=110, bbox_inches="tight")
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
