"""The experiment scripts (plot_convergence, compare_images, report) on small synthetic results,
and once end to end on what `photonlab run` writes, down to a headless-Chromium screenshot of
index.html that must show the images and the plots."""
import csv
import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SCRIPTS = os.path.join(ROOT, "scripts")
PHOTONLAB = os.path.join(ROOT, "build", "photonlab")
sys.path.insert(0, SCRIPTS)
import experiment_results as er  # noqa: E402
import plot_convergence  # noqa: E402
import report  # noqa: E402

COLUMNS = ["run", "label", "integrator", "seed", "checkpoint", "seconds", "spp", "passes", "photons", "rmse",
           "relmse", "mae", "mean_ratio", "mean_radius", "final", "image"]
RED, GREEN, BLUE = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def write_exr(path, rgb, w=32, h=24):
    img = np.zeros((h, w, 3), dtype=np.float32)
    img[:, :] = rgb
    os.makedirs(os.path.dirname(path), exist_ok=True)
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(w, h, 3, oiio.FLOAT))
    out.write_image(img)
    out.close()


def write_png(path, rgb, w=32, h=24):
    img = np.zeros((h, w, 3), dtype=np.uint8)
    img[:, :] = [int(255 * c) for c in rgb]
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(w, h, 3, oiio.UINT8))
    out.write_image(img)
    out.close()


def synthetic_results(tmp_path, columns=COLUMNS):
    """Two runs: 'A' (path, 2 seeds, relMSE ∝ 1/spp) and 'B' (sppm, 1 seed, ∝ passes^(-2/3)); a
    red reference, a green image for A and a blue one for B."""
    d = tmp_path / "results"
    write_exr(str(d / "reference.exr"), RED)
    write_png(str(d / "reference.png"), RED)
    rows = []
    for seed, scale in [(1, 1.0), (2, 2.0)]:
        for i, spp in enumerate([1, 2, 4, 8], start=1):
            img = f"runs/01-a/seed-{seed}/spp-{spp:04d}.exr"
            rows.append(dict(run=1, label="A, path", integrator="path", seed=seed, checkpoint=i, seconds=0.1 * spp,
                             spp=spp, passes=0, photons=0, rmse=(scale / spp) ** 0.5, relmse=scale / spp,
                             mae=0.1, mean_ratio=1.0, mean_radius=0, final=int(spp == 8), image=img))
        write_exr(str(d / f"runs/01-a/seed-{seed}/spp-0008.exr"), GREEN)
        write_exr(str(d / f"runs/01-a/seed-{seed}/final.exr"), GREEN)
        write_png(str(d / f"runs/01-a/seed-{seed}/final.png"), GREEN)
    for i, passes in enumerate([1, 2, 4, 8, 16], start=1):
        img = f"runs/02-b/seed-1/pass-{passes:04d}.exr"
        rows.append(dict(run=2, label="B", integrator="sppm", seed=1, checkpoint=i, seconds=0.2 * passes, spp=0,
                         passes=passes, photons=1000 * passes, rmse=passes ** (-1 / 3), relmse=passes ** (-2 / 3),
                         mae=0.1, mean_ratio=0.99, mean_radius=0.01, final=int(passes == 16), image=img))
    write_exr(str(d / "runs/02-b/seed-1/pass-0016.exr"), BLUE)
    write_exr(str(d / "runs/02-b/seed-1/final.exr"), BLUE)
    write_png(str(d / "runs/02-b/seed-1/final.png"), BLUE)
    with open(d / "metrics.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    (d / "experiment.toml").write_text('name = "synthetic"\nwidth = 32\nheight = 24\ninset = [4, 4, 8, 8]\n'
                                       '[provenance]\ngit_revision = "abc"\ncores = "2"\ncpu = "Test CPU"\n')
    return str(d)


def run_script(name, *args):
    return subprocess.run([sys.executable, os.path.join(SCRIPTS, name), *args], capture_output=True, text=True)


def test_curves_take_geometric_mean_and_band_over_seeds(tmp_path):
    runs = er.runs(er.read_metrics(synthetic_results(tmp_path)))
    xs, ys, lo, hi = plot_convergence.curves(runs[1], er.work_of, "relmse")
    assert xs == [1, 2, 4, 8]
    assert ys == pytest.approx([2 ** 0.5 / s for s in xs])  # geometric mean of 1/spp and 2/spp
    assert lo == pytest.approx([1 / s for s in xs]) and hi == pytest.approx([2 / s for s in xs])
    xs, ys, _, _ = plot_convergence.curves(runs[2], er.work_of, "relmse")
    slope = np.polyfit(np.log(xs), np.log(ys), 1)[0]
    assert slope == pytest.approx(-2 / 3)


def test_plots_and_report_are_written(tmp_path):
    d = synthetic_results(tmp_path)
    for script, stem in [("plot_convergence.py", "convergence"), ("compare_images.py", "comparison")]:
        r = run_script(script, d)
        assert r.returncode == 0, r.stderr
        for ext in ("png", "pdf"):
            path = os.path.join(d, f"{stem}.{ext}")
            assert os.path.getsize(path) > 1000
        assert open(os.path.join(d, f"{stem}.png"), "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    r = run_script("report.py", d)
    assert r.returncode == 0, r.stderr
    page = open(os.path.join(d, "index.html"), encoding="utf-8").read()
    assert "A, path" in page and "<table>" in page
    assert "<h2>Summary</h2>" in page and "speed-up over A, path" in page
    assert "Test CPU" in page  # the machine
    # Means over seeds in the table: relMSE of A's finals is (1/8 + 2/8)/2.
    assert f"{(1 / 8 + 2 / 8) / 2:.4g}" in page
    # Every relative link resolves: the page works offline and moves with the folder.
    import re
    for link in re.findall(r'(?:src|href)="([^"]+)"', page):
        assert os.path.exists(os.path.join(d, link)), link


@pytest.mark.parametrize("script", ["plot_convergence.py", "compare_images.py", "report.py"])
def test_a_missing_column_is_a_one_line_error(tmp_path, script):
    d = synthetic_results(tmp_path, columns=[c for c in COLUMNS if c != "relmse"])
    r = run_script(script, d)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1
    assert "metrics.csv: missing column(s) relmse" in r.stderr


def test_bad_folders_and_values_are_one_line_errors(tmp_path):
    r = run_script("report.py", str(tmp_path / "nowhere"))
    assert r.returncode == 2 and "no such file" in r.stderr and "Traceback" not in r.stderr
    d = synthetic_results(tmp_path)
    text = open(os.path.join(d, "metrics.csv")).read().replace(",0.1,", ",zero,", 1)
    open(os.path.join(d, "metrics.csv"), "w").write(text)
    r = run_script("plot_convergence.py", d)
    assert r.returncode == 2 and "not a number" in r.stderr and "Traceback" not in r.stderr


def test_relmse_map_is_photonlabs_relmse():
    rng = np.random.default_rng(1)
    ref = rng.uniform(0, 2, (8, 8, 3))
    img = ref + rng.normal(0, 0.1, ref.shape)
    expected = np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))
    assert er.relmse_map(img, ref).mean() == pytest.approx(expected, rel=1e-12)


def test_summary_equal_time_time_to_target_and_speedup_on_power_laws(tmp_path):
    # A: relMSE = √2/spp (geometric mean of its two seeds) at t = 0.1·spp s, 1..8 spp.
    # B: relMSE = passes^(−2/3) at t = 0.2·passes s, 1..16 passes. Both straight lines in
    # log–log, so interpolation between checkpoints is exact:
    #   equal time = the shorter final time, 0.8 s: A √2/8, B at 4 passes 4^(−2/3);
    #   target = the baseline's (A's) final relMSE, √2/8; B reaches it at passes = (√2/8)^(−3/2),
    #   t = 0.2 · that = 2.691 s; speed-up of B over the baseline A = 0.8 / 2.691.
    rows = er.read_metrics(synthetic_results(tmp_path))
    table, equal_time, target, baseline = report.summary_table(rows, {})
    assert equal_time == pytest.approx(0.8)
    assert target == pytest.approx(2 ** 0.5 / 8)
    assert baseline == "A, path"
    a, b = table
    assert a["relmse_at_equal_time"] == pytest.approx(2 ** 0.5 / 8)
    assert b["relmse_at_equal_time"] == pytest.approx(4 ** (-2 / 3))
    tb = 0.2 * (2 ** 0.5 / 8) ** (-1.5)
    assert a["time_to_target"] == pytest.approx(0.8)
    assert b["time_to_target"] == pytest.approx(tb)
    assert a["speedup"] == pytest.approx(1.0) and a["baseline"]
    assert b["speedup"] == pytest.approx(0.8 / tb)
    # B as the baseline: the target is B's final relMSE, 16^(−2/3) = 0.157, reached by B at its
    # end (3.2 s); A would need spp = √2·16^(2/3) = 9.0 > 8, beyond its last checkpoint: never.
    table, _, target, _ = report.summary_table(rows, {"baseline": "B"})
    assert target == pytest.approx(16 ** (-2 / 3))
    assert table[1]["time_to_target"] == pytest.approx(3.2)
    assert table[0]["time_to_target"] is None and table[0]["speedup"] is None
    # A chosen baseline and target: B reaches relMSE 0.2 at passes 0.2^(−3/2).
    table, _, target, baseline = report.summary_table(rows, {"baseline": "B", "target_relmse": 0.2})
    assert baseline == "B" and target == 0.2
    assert table[1]["time_to_target"] == pytest.approx(0.2 * 0.2 ** -1.5)
    assert table[1]["speedup"] == pytest.approx(1.0)
    # A curve that never gets there: no time, no speed-up.
    assert er.loglog_time_to([1, 2, 4], [0.5, 0.4, 0.35], 0.1) is None
    assert er.loglog_at([1, 10], [1.0, 0.1], 3.0) == pytest.approx(1 / 3)
    assert er.loglog_at([1, 10], [1.0, 0.1], 20) is None


def test_convergence_plot_guides_through_each_last_point_and_a_legend_in_every_panel(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    xs, ys = [1, 2, 4, 8, 16, 32], [1.0, 0.5, 0.3, 0.2, 0.1, 0.05]
    plot_convergence.slope_guides(ax, xs, ys, "rmse", "C0")
    for line, slope in zip(ax.get_lines(), [-0.5, -1 / 3]):  # RMSE: half the MSE slopes
        (x0, x1), (y0, y1) = line.get_data()
        assert (x1, y1) == (32, 0.05)  # anchored at the last point
        assert x0 == pytest.approx(3.2)  # one decade back
        assert np.log(y1 / y0) / np.log(x1 / x0) == pytest.approx(slope)
    plt.close(fig)
    d = synthetic_results(tmp_path)
    figure = {}
    orig = er.save_figure
    er.save_figure = lambda fig, prefix: figure.setdefault("fig", fig) and []
    try:
        plot_convergence.plot(d, str(tmp_path / "c"))
    finally:
        er.save_figure = orig
    axes = figure["fig"].get_axes()
    assert len(axes) == 6  # relMSE, RMSE, mean ratio × time, work
    assert all(ax.get_legend() is not None for ax in axes)
    assert {ax.get_xlabel() for ax in axes} == {"render time (s)", "samples per pixel, or photon passes"}


def test_log_axes_have_several_labelled_ticks_and_report_numbers_are_rounded():
    # An RMSE falling from 0.03 to 0.008 spans 0.6 decades: matplotlib's default would label
    # 0.01 alone; the readable axis labels 1, 2 and 5 times the powers of ten inside it.
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    ax.plot([1, 2, 4, 8], [0.03, 0.02, 0.012, 0.008])
    ax.set_xscale("log")
    ax.set_yscale("log")
    er.readable_log_axis(ax.yaxis)
    fig.canvas.draw()
    lo, hi = sorted(ax.get_ylim())
    labelled = [t.get_text() for t, v in zip(ax.get_yticklabels(), ax.get_yticks()) if lo <= v <= hi and t.get_text()]
    assert len(labelled) >= 3, labelled
    assert "0.01" in labelled and "0.02" in labelled
    # Wide ranges keep the powers of ten.
    ax.set_ylim(1e-6, 1)
    er.readable_log_axis(ax.yaxis)
    plt.close(fig)
    assert er.readable_number(2 / 3) == "0.6667"
    assert er.readable_number(64) == "64" and er.readable_number("sppm") == "sppm"


def test_signed_difference_and_display_transforms():
    ref = np.full((2, 2, 3), 0.4)
    img = ref.copy()
    img[0, 0] = 0.6  # too bright: +0.2/(0.4 + 0.1)
    img[1, 1] = 0.2  # too dark
    d = er.signed_difference_map(img, ref)
    assert d[0, 0] == pytest.approx(0.4) and d[1, 1] == pytest.approx(-0.4) and d[0, 1] == 0
    # The same curves as photonlab's PNGs (src/image/tonemap.h): clamp by default; Narkowicz's ACES.
    x = np.array([0.0, 0.25, 1.0, 4.0, 100.0])
    assert np.allclose(er.to_display(x), er.to_srgb(x))
    f = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)
    srgb = lambda v: np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)  # noqa: E731
    assert np.allclose(er.to_display(x, 0, "aces"), srgb(np.minimum(f, 1)))
    assert np.allclose(er.to_display(x, 1.0), er.to_display(2 * x))
    # An inset whose brightest pixels are at 50: exposure lowered so they land at 4 (not white).
    inset = np.full((10, 10, 3), 0.5)
    inset[0, :3] = 50.0
    ev = er.inset_exposure(inset, 0.0)
    assert 2 ** ev * 50 == pytest.approx(4.0, rel=0.05)
    assert er.to_display(inset * 2 ** ev, 0, "aces").max() < 0.99
    assert er.inset_exposure(np.full((4, 4, 3), 0.5), 0.0) == 0.0  # nothing bright: unchanged


def screenshot(html, png, size="1200,2600"):
    chromium = shutil.which("chromium")
    assert chromium, "chromium is missing: scripts/setup.sh installs it"
    r = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                        f"--screenshot={png}", f"--window-size={size}", "file://" + os.path.abspath(html)],
                       capture_output=True, text=True, timeout=120)
    assert os.path.isfile(png), r.stderr
    return oiio.ImageBuf(png).get_pixels(oiio.UINT8)[:, :, :3].astype(int)


def fraction_near(pixels, rgb, tolerance=30):
    return np.mean(np.all(np.abs(pixels - np.array(rgb)) <= tolerance, axis=2))


def test_report_in_headless_chromium_shows_images_and_plots(tmp_path):
    d = synthetic_results(tmp_path)
    assert run_script("report.py", d).returncode == 0
    px = screenshot(os.path.join(d, "index.html"), str(tmp_path / "shot.png"))
    # The reference (red) and the two runs' images (green, blue) are on the page, as <img>s and in
    # the comparison figure; the plot's first line is matplotlib's C0 blue.
    assert fraction_near(px, (255, 0, 0)) > 0.005
    assert fraction_near(px, (0, 255, 0)) > 0.005
    assert fraction_near(px, (0, 0, 255)) > 0.005
    assert fraction_near(px, (31, 119, 180), tolerance=12) > 0.0001  # ~300 pixels of line
    assert fraction_near(px, (255, 255, 255)) < 0.95  # not a blank page


def test_end_to_end_photonlab_run_then_report(tmp_path):
    assert os.access(PHOTONLAB, os.X_OK), "build/photonlab is missing: run scripts/setup.sh"
    config = tmp_path / "e2e.toml"
    config.write_text(f'name = "e2e"\nscene = "{ROOT}/scenes/cornell-box.gltf"\nwidth = 24\ninset = [0, 0, 8, 8]\n'
                      '[reference]\nintegrator = "path"\nspp = 64\n'
                      '[[run]]\nlabel = "Path"\nintegrator = "path"\nspp = 8\nseeds = [1, 2]\n'
                      '[[run]]\nlabel = "SPPM"\nintegrator = "sppm"\npasses = 4\nphotons_per_pass = 5000\n')
    r = subprocess.run([PHOTONLAB, "run", str(config), "--out", str(tmp_path / "out"), "-q"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = r.stdout.strip()
    rows = er.read_metrics(out)
    assert {row["label"] for row in rows} == {"Path", "SPPM"}
    r = run_script("report.py", out)
    assert r.returncode == 0, r.stderr
    table = report.final_table(rows)
    assert [t["label"] for t in table] == ["Path", "SPPM"] and table[0]["seeds"] == 2
    # The path tracer's error falls roughly as 1/spp between 1 and 8 spp (two seeds).
    path = er.runs(rows)[1]
    xs, ys, _, _ = plot_convergence.curves(path, er.work_of, "relmse")
    assert xs == [1, 2, 4, 8]
    slope = np.polyfit(np.log(xs), np.log(ys), 1)[0]
    assert -1.4 < slope < -0.6
    px = screenshot(os.path.join(out, "index.html"), str(tmp_path / "shot.png"))
    assert fraction_near(px, (255, 255, 255)) < 0.97
    # The report states its reference: integrator, seed (its own stream), work and time.
    page = open(os.path.join(out, "index.html"), encoding="utf-8").read()
    assert "<h2>Reference</h2>" in page and "Integrator <b>path</b>" in page and "seed -1" in page
    assert "64 spp" in page and "rendered in" in page


def test_results_pages_fill_marked_blocks_only(tmp_path):
    import results_pages
    d = synthetic_results(tmp_path)
    write_exr(os.path.join(d, "reference.exr"), RED)
    docs = tmp_path / "pages"
    (docs / "results").mkdir(parents=True)
    page = docs / "results" / "x.md"
    page.write_text("intro\n<!-- experiment:synthetic:begin -->\nold numbers\n<!-- experiment:synthetic:end -->\ntail\n")
    untouched = docs / "other.md"
    untouched.write_text("nothing marked\n")
    assert results_pages.main(["--docs", str(docs), "--experiment", d]) == 0
    text = page.read_text()
    assert text.startswith("intro\n") and text.endswith("tail\n") and "old numbers" not in text
    assert "| A, path | 2 |" in text and "| B | 1 |" in text
    assert "results_pages.py --experiment" in text  # the block says how it was made
    assert not re.search(r"\b[0-9a-f]{12}\b", text)  # and names no commit
    assert untouched.read_text() == "nothing marked\n"
    # Idempotent, and a block no page has is an error that leaves every page alone.
    assert results_pages.main(["--docs", str(docs), "--experiment", d]) == 0
    assert page.read_text() == text
    table = tmp_path / "table.md"
    table.write_text("| a | b |\n|---|---|\n| 1 | 2 |\n")
    assert results_pages.main(["--docs", str(docs), "--table", "smallvcm", str(table)]) == 2
    assert page.read_text() == text
    # A table printed by a comparison script goes into its own block.
    page.write_text(text + "<!-- smallvcm:begin -->\nold\n<!-- smallvcm:end -->\n")
    assert results_pages.main(["--docs", str(docs), "--table", "smallvcm", str(table)]) == 0
    assert "| 1 | 2 |" in page.read_text() and "\nold\n" not in page.read_text()


def test_strategy_grid_lays_techniques_out_by_depth_and_says_when_there_are_none(tmp_path):
    # bdpt --aov strategies writes OUT.exr and OUT.s<S>t<T>.exr; the grid has one row per depth.
    write_exr(str(tmp_path / "st.exr"), GREEN)
    for s, t in [(0, 2), (1, 1), (0, 3), (1, 2), (2, 1)]:
        write_exr(str(tmp_path / ("st.s%dt%d.exr" % (s, t))), RED)
    out = tmp_path / "grid.png"
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "strategy_grid.py"), str(tmp_path / "st.exr"),
                        "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    spec = oiio.ImageInput.open(str(out)).spec()
    assert spec.height > 0 and spec.width > spec.height  # two rows (depths 0, 1) of four columns
    write_exr(str(tmp_path / "lone.exr"), GREEN)
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "strategy_grid.py"), str(tmp_path / "lone.exr")],
                       capture_output=True, text=True)
    assert r.returncode != 0 and "--aov strategies" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_compare_smallvcm_refuses_a_source_it_cannot_patch(tmp_path):
    # The script changes one line of SmallVCM's main to report iterations; a different source
    # is a one-line error, not a table without iteration counts.
    src = tmp_path / "svcm" / "src"
    src.mkdir(parents=True)
    (src / "smallvcm.cxx").write_text("int main() { return 0; }\n")
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare_smallvcm.py"), "--smallvcm-src",
                        str(tmp_path / "svcm"), "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert r.returncode != 0 and "unrecognised src/smallvcm.cxx" in r.stderr


def test_compare_smallvcm_first_run_draws_other_seeds_and_reports_the_median(tmp_path, monkeypatch):
    # Runs 0-5 of every earlier comparison drew the same seeds, hence the same fireflies. Run k
    # must use photonlab seed k + 1 and SmallVCM base seed 2000 + 100 k (its threads add 0, 1),
    # and --first-run K must start at run K. Renderers and metrics are stubs; each run's relMSE
    # is its seed squared, so that the mean and the median differ and are known.
    import compare_smallvcm as cs
    calls, seed_of = [], {}

    def render(code, work):
        def run(binary, scene, method, seconds, output, seed=0, **kw):
            calls.append((code, seed, os.path.basename(output)))
            seed_of[output] = seed
            return 20.0, work
        return run

    out = tmp_path / "out"
    out.mkdir()
    for ref in ("ref-photonlab-point.exr", "ref-smallvcm-point.hdr"):
        (out / ref).write_text("")  # present: no reference render
    monkeypatch.setattr(cs, "build_smallvcm", lambda src, out_dir: "smallvcm")
    monkeypatch.setattr(cs, "run_photonlab", render("photonlab", "40 iterations"))
    monkeypatch.setattr(cs, "run_smallvcm", render("smallvcm", "30 iterations"))
    monkeypatch.setattr(cs, "relmse", lambda photonlab, image, reference: float(seed_of[image]) ** 2)
    monkeypatch.setattr(cs, "trimmed_relmse", lambda image, reference: 0.5)
    monkeypatch.setattr(sys, "argv", ["compare_smallvcm.py", "--smallvcm-src", str(tmp_path), "--out", str(out),
                                      "--scenes", "point", "--methods", "bdpt:bpt", "--first-run", "6",
                                      "--repeats", "3"])
    cs.main()
    assert calls == [("photonlab", 7, "photonlab-point-bdpt-6.exr"), ("smallvcm", 2600, "smallvcm-point-bpt-6.hdr"),
                     ("photonlab", 8, "photonlab-point-bdpt-7.exr"), ("smallvcm", 2700, "smallvcm-point-bpt-7.hdr"),
                     ("photonlab", 9, "photonlab-point-bdpt-8.exr"), ("smallvcm", 2800, "smallvcm-point-bpt-8.hdr")]
    rows = (out / "table.md").read_text().strip().splitlines()
    # photonlab: 49, 64, 81 (mean 64.6667, median 64); SmallVCM: 2600², 2700², 2800².
    assert rows[2].startswith("| point | photonlab | `bdpt` | 40 iterations | 20.0 s | 64.6667 | 64.0000 | 0.5000 |")
    assert rows[3].startswith("| point | SmallVCM | `bpt` | 30 iterations | 20.0 s | 7296666.6667 | 7290000.0000 | 0.5000 |")
    # The pair's ratios: 64.67 / 7.3e6 and 64 / 7.29e6 round to 0.00; the best-99% means are equal.
    assert rows[-1] == "| point | `bdpt` / `bpt` | 3 | 0.00 (0.00–0.00) | 0.00 (0.00–0.00) | 1.00 |"


def test_compare_smallvcm_ratio_of_means_and_its_bootstrap_interval():
    import compare_smallvcm as cs
    # Runs without spread: the ratio is exact and so is every resample's.
    assert cs.ratio_of_means([2.0, 2.0, 2.0], [4.0, 4.0, 4.0, 4.0]) == (0.5, 0.5, 0.5)
    # Coverage: 200 comparisons of 30 runs each, photonlab's relMSE lognormal with mean 0.8 and
    # SmallVCM's with mean 1 (σ = 0.6 in the log: a 20 s run's spread). A 90% interval should
    # hold the true ratio 0.8 in about 90% of them; the binomial standard deviation over 200 is
    # 2.1%, and the percentile bootstrap of a mean of 30 skewed runs covers a little less than
    # its level, so 82–97% (an interval that ignored either codebase's spread would cover far
    # less, one that was too wide all 200 times).
    rng = np.random.default_rng(7)
    sigma = 0.6
    covered = 0
    for _ in range(200):
        ours = 0.8 * np.exp(rng.normal(-sigma * sigma / 2, sigma, 30))
        theirs = np.exp(rng.normal(-sigma * sigma / 2, sigma, 30))
        r, lo, hi = cs.ratio_of_means(ours, theirs, resamples=1000)
        assert lo <= r <= hi
        covered += lo <= 0.8 <= hi
    assert 0.82 * 200 <= covered <= 0.97 * 200


def test_compare_smallvcm_ratio_of_medians_holds_where_runs_have_no_finite_mean():
    import compare_smallvcm as cs
    # The medians 2 and 4, whatever the 30; resampled medians lie between 1/4 and 30/2.
    r, lo, hi = cs.ratio_of_medians([1.0, 2.0, 30.0], [2.0, 4.0, 4.0])
    assert r == 0.5 and 0.25 <= lo <= r <= hi <= 15.0
    # Runs whose relMSE is a floor plus a Pareto excess of index 0.75 (no finite mean: what
    # single samples of tail index 1.5 give a run's squared error), photonlab's 0.8× SmallVCM's
    # in distribution. The ratio of the medians is then 0.8 for every sample size; its 90%
    # interval should hold 0.8 in about 90% of 200 comparisons of 40 runs: binomial standard
    # deviation 2.1%, and a bootstrap median interval is a little conservative (the resampled
    # medians take few values), so 86–99%.
    rng = np.random.default_rng(5)
    covered = 0
    for _ in range(200):
        ours, theirs = (scale * (0.01 + 0.004 * (rng.uniform(size=40) ** (-1 / 0.75) - 1)) for scale in (0.8, 1.0))
        r, lo, hi = cs.ratio_of_medians(ours, theirs, resamples=1000)
        assert lo <= r <= hi
        covered += lo <= 0.8 <= hi
    assert 0.86 * 200 <= covered <= 0.99 * 200


def test_compare_smallvcm_tail_counts_bright_samples_in_exr_and_hdr_and_tabulates_rates(tmp_path):
    # --tail counts, in one-iteration images, the pixels whose largest channel exceeds each
    # threshold; SmallVCM writes Radiance .hdr, photonlab EXR: both must read the same.
    import compare_smallvcm as cs
    img = np.full((24, 32, 3), 0.5, dtype=np.float32)
    img[1, 2] = (60.0, 0.0, 0.0)        # above 50 only
    img[3, 4] = (0.0, 0.0, 250.0)       # above 50, 100, 200
    img[5, 6] = (1500.0, 1500.0, 1.0)   # above every threshold
    for name in ("a.exr", "a.hdr"):
        path = str(tmp_path / name)
        out = oiio.ImageOutput.create(path)
        out.open(path, oiio.ImageSpec(32, 24, 3, oiio.FLOAT))
        out.write_image(img)
        out.close()
        above, mean, values = cs.count_above(path)
        assert above == [3, 2, 2, 1, 1], name
        assert mean == pytest.approx(float(img.mean()), rel=0.01), name  # RGBE keeps ~1% per value
        assert sorted(values) == pytest.approx([60.0, 250.0, 1500.0], rel=0.01), name  # above 50, for the fit
    # Rates per 100 iterations with the Poisson standard error sqrt(n): 4 in 200 -> 2.0 ± 1.0;
    # the tail index of samples 50·e and 50·e³: above 50, α̂ = 2 / (1 + 3) = 0.5, ± 0.5/√2; above
    # 100, 2 / (1 + 3 − 2 ln 2) = 0.765, ± 0.765/√2.
    values = [50 * np.e, 50 * np.e ** 3]
    text = cs.tail_table({("point", "photonlab", "bdpt"): ([4, 1, 0, 0, 0], 100.0, values)}, 200)
    row = text.strip().splitlines()[-1]
    assert row.startswith("| point | photonlab | `bdpt` | 200 | 0.5000 | 2.0 ± 1.0 | 0.5 ± 0.5 | 0.0 ± 0.0 |")
    assert row.endswith("| 0.50 ± 0.35 (2) | 0.77 ± 0.54 (2) |")


def test_compare_smallvcm_tail_index_recovers_a_pareto_tail():
    # Hill's estimator on samples drawn from a Pareto tail of known index, above a threshold:
    # P(X > x) = (x/x_m)^−α, x_m = 1. Above u the tail is again Pareto with the same α, so the
    # fit must find the generating α within its standard error α/√n; 4 standard errors (the
    # fixed seed makes this one draw, which a correct estimator misses with probability 6e-5).
    import compare_smallvcm as cs
    rng = np.random.default_rng(11)
    for alpha in (1.5, 3.0):
        x = rng.uniform(size=20000) ** (-1.0 / alpha)  # inverse CDF of the Pareto law
        for u in (2.0, 5.0):
            a, se, n = cs.tail_index(x, u)
            assert n == int((x > u).sum())
            assert se == pytest.approx(a / np.sqrt(n))
            assert abs(a - alpha) < 4 * alpha / np.sqrt(n), (alpha, u, a, n)
    # An exponential tail is lighter than any power law: the fit reads a large index, growing
    # with the threshold (α̂ = u for an exponential of rate 1 above u, roughly).
    y = rng.exponential(size=20000)
    assert cs.tail_index(y, 3.0)[0] > 2.5 and cs.tail_index(y, 5.0)[0] > 4.0
    # Nothing above the threshold: no fit.
    assert np.isnan(cs.tail_index([1.0, 2.0], 5.0)[0])


def test_image_readers_see_a_file_rewritten_under_the_same_name(tmp_path):
    # compare_smallvcm.py --tail renders every iteration to one file name; OpenImageIO's shared
    # image cache (behind ImageBuf) returned the previous pixels of a file rewritten within the
    # same second. Each reader must see every version of the file.
    import compare_smallvcm as cs
    for name in ("same.exr", "same.hdr"):
        path = str(tmp_path / name)
        for k in range(5):
            img = np.full((24, 32, 3), float(k + 1), dtype=np.float32)
            out = oiio.ImageOutput.create(path)
            out.open(path, oiio.ImageSpec(32, 24, 3, oiio.FLOAT))
            out.write_image(img)
            out.close()
            assert cs.read_rgb(path).mean() == pytest.approx(k + 1, rel=0.01), (name, k)
            if name.endswith(".exr"):
                assert er.read_exr(path).mean() == pytest.approx(k + 1), k


def test_compare_smallvcm_trimmed_relmse_leaves_out_the_worst_pixels(tmp_path):
    # 100 pixels: 98 off by 10% of a reference of 1 (relMSE 0.01/1.01 each), one off by 1 (1/1.01)
    # and one firefly of 1000. The best 99% keep the 98 and the one off by 1:
    # (98 · 0.01 + 1) / 1.01 / 99; the whole image's mean would be dominated by the firefly.
    import compare_smallvcm as cs
    ref = np.ones((10, 10, 3), dtype=np.float32)
    img = np.full((10, 10, 3), 1.1, dtype=np.float32)
    img[0, 0] = 2.0
    img[9, 9] = 1001.0
    paths = []
    for name, data in (("img.exr", img), ("ref.exr", ref)):
        path = str(tmp_path / name)
        out = oiio.ImageOutput.create(path)
        out.open(path, oiio.ImageSpec(10, 10, 3, oiio.FLOAT))
        out.write_image(data)
        out.close()
        paths.append(path)
    expected = (98 * 0.01 + 1.0) / 1.01 / 99
    assert cs.trimmed_relmse(paths[0], paths[1]) == pytest.approx(expected, rel=1e-5)
    assert cs.trimmed_relmse(paths[0], paths[1], keep=1.0) == pytest.approx((98 * 0.01 + 1 + 1000 ** 2) / 1.01 / 100, rel=1e-5)


def test_radiosity_convergence_tabulates_every_budget_and_draws_the_figure(tmp_path):
    # Two small budgets on the Cornell box at 16 px: one table row each (patches growing with
    # the budget, both displays' errors), the figure written; a missing binary is one line.
    assert os.access(PHOTONLAB, os.X_OK), "build/photonlab is missing: run scripts/setup.sh"
    figure = tmp_path / "fig.png"
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "radiosity_convergence.py"), "--width", "16",
                        "--budgets", "100,400", "--reference-spp", "16", "--gather-spp", "4", "--smooth-spp", "4",
                        "--out", str(tmp_path / "out"), "--figure", str(figure)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows = [line for line in r.stdout.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == 2
    patches = [int(row.split("|")[1]) for row in rows]
    assert patches[0] < patches[1] <= 400
    assert oiio.ImageInput.open(str(figure)).spec().width > 0
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "radiosity_convergence.py"), "--binary",
                        str(tmp_path / "none"), "--out", str(tmp_path / "o2")], capture_output=True, text=True)
    assert r.returncode != 0 and "no photonlab binary" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_load_benchmark_writes_loadable_grids_and_reads_the_bench_table(tmp_path):
    """load_benchmark.py's files: the grid's triangle count, its normals facing up (the height
    field's), and 4 placements of one mesh stored once; then its whole table on tiny grids."""
    import load_benchmark as lb
    positions, normals, uvs, triangles = lb.grid_arrays(5)
    assert positions.shape == (25, 3) and triangles.shape == (32, 3)
    # Counter-clockwise seen from +y: every face normal points up, as the vertex normals do.
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    assert (np.cross(b - a, c - a)[:, 1] > 0).all()
    assert (normals[:, 1] > 0).all()
    path = str(tmp_path / "g.glb")
    assert lb.write_glb(path, 5, attributes=True, placements=4) == 128
    info = subprocess.run([PHOTONLAB, "info", path], check=True, capture_output=True, text=True).stdout
    assert "triangles: 128 (32 stored" in info and "4 instances" in info
    rows = lb.bench(PHOTONLAB, path, 1)
    assert rows["triangles (stored)"] == "128 (32)"
    # The file's geometry: 25 vertices x (12 + 12 + 8) bytes + 96 indices x 4 bytes.
    assert float(rows["geometry in the file (MB)"]) == pytest.approx((25 * 32 + 96 * 4) / 1e6, abs=0.05)
    assert subprocess.run([sys.executable, os.path.join(SCRIPTS, "load_benchmark.py"), "--size", "8", "--repeats", "1",
                           "--dir", str(tmp_path / "files")], check=True, capture_output=True, text=True).stdout.count("\n") == 5


def test_gallery_renders_models_from_a_folder_or_a_url_of_the_khronos_layout(tmp_path):
    """gallery.py on a stand-in for Khronos' Models/: a .glb, and a .gltf whose buffer is an
    external file, taken from the folder directly and through a file:// URL (downloaded into the
    cache, the .gltf's buffer with it); a model that is missing is named, the rest rendered."""
    import gallery
    import load_benchmark as lb
    models = tmp_path / "Models"
    lb.write_glb(_make_dirs(models / "DamagedHelmet" / "glTF-Binary") + "/DamagedHelmet.glb", 4)
    # ToyCar as a .gltf with its buffer beside it: the glb's JSON with the BIN chunk moved to a file.
    glb = open(models / "DamagedHelmet" / "glTF-Binary" / "DamagedHelmet.glb", "rb").read()
    json_length = int.from_bytes(glb[12:16], "little")
    doc = json.loads(glb[20:20 + json_length])
    bin_chunk = glb[20 + json_length + 8:]
    doc["buffers"][0]["uri"] = "ToyCar data.bin"
    gltf_dir = _make_dirs(models / "ToyCar" / "glTF")
    open(gltf_dir + "/ToyCar data.bin", "wb").write(bin_chunk)
    json.dump(doc, open(gltf_dir + "/ToyCar.gltf", "w"))
    common = ["--models", "DamagedHelmet,ToyCar,WaterBottle", "--width", "16", "--spp", "2", "--time", "10",
              "--photonlab", PHOTONLAB]
    for source, out in ((str(models), tmp_path / "local"), ((tmp_path / "Models").as_uri(), tmp_path / "remote")):
        assert gallery.main(["--source", source, "--cache", str(tmp_path / "cache"), "--out", str(out)] + common) == 0
        table = open(out / "gallery.md").read()
        assert "![DamagedHelmet](DamagedHelmet.png)" in table and "![ToyCar](ToyCar.png)" in table
        assert "WaterBottle" not in table  # not in the source: skipped, said on stderr
        assert os.path.getsize(out / "DamagedHelmet.png") > 0 and os.path.getsize(out / "ToyCar.png") > 0
    assert os.path.isfile(tmp_path / "cache" / "ToyCar" / "glTF" / "ToyCar data.bin")


def _make_dirs(path):
    os.makedirs(path, exist_ok=True)
    return str(path)


@pytest.mark.slow
def test_profile_guided_build_renders_the_plain_build_s_images_bit_for_bit(tmp_path):
    # scripts/build_pgo.sh: instrumented build, training renders, rebuild with the profile.
    # No flag it adds may change floating-point results, so every integrator's image must be the
    # plain build's to the last bit: scripts/compare_builds.sh (every integrator, rmse 0) on a
    # scene with glass, a mirror and an area light, on SmallVCM's point-light box, and in
    # spectral mode. The profiles must exist (the training ran and wrote them where the second
    # stage reads them).
    if not os.path.exists(PHOTONLAB):
        pytest.skip("needs the build")
    out = tmp_path / "build-pgo"
    r = subprocess.run(["bash", os.path.join(SCRIPTS, "build_pgo.sh"), str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    assert any(name.endswith(".gcda") for name in os.listdir(out / "pgo-profile"))
    scenes = os.path.join(ROOT, "scenes")
    for files, options in (("cornell-spheres.gltf smallvcm-point.gltf", []), ("cornell-spheres.gltf", ["--spectral"])):
        env = dict(os.environ, SCENES=" ".join(os.path.join(scenes, f) for f in files.split()))
        r = subprocess.run(["bash", os.path.join(SCRIPTS, "compare_builds.sh"), PHOTONLAB, str(out / "photonlab")]
                           + options, capture_output=True, text=True, env=env)
        assert r.returncode == 0 and "all bit-identical" in r.stdout, (files, options, r.stdout, r.stderr[-2000:])
        compared = int(r.stdout.split(" renders compared")[0].split()[-1])
        assert compared >= 12 * len(files.split())  # every integrator on every scene, none skipped


def test_src_folders_are_layered_without_cycles(tmp_path):
    import check_layers
    problems, order = check_layers.check(os.path.join(ROOT, "src"))
    assert problems == [], "\n".join(problems)
    assert order[0].split()[1] == "core" and len(order) == len(check_layers.LAYERS)
    # A tree with a cycle and a climbing include fails, naming the file and the line.
    for folder, name, text in [("core", "a.h", '#include "scene/b.h"\n'), ("scene", "b.h", '#include <vector>\n#include "core/a.h"\n'),
                               ("spectral", "c.cpp", '#include "core/a.h"\n')]:
        os.makedirs(tmp_path / folder, exist_ok=True)
        (tmp_path / folder / name).write_text(text)
    problems, _ = check_layers.check(str(tmp_path))
    assert "cycle between the folders core, scene" in problems
    assert "src/core/a.h:1: core/ includes scene/, a layer above it" in problems
    assert not any("spectral" in p for p in problems)
    (tmp_path / "newfolder").mkdir()
    assert any("newfolder" in p for p in check_layers.check(str(tmp_path))[0])
    assert run_script("check_layers.py", "--quiet", "--src", str(tmp_path)).returncode == 1


def test_compare_convergence_agrees_with_itself_and_tells_a_different_estimate(tmp_path):
    # The same build twice: every region's z is 0. A "build" that stops paths after one bounce
    # (a wrapper adding --max-depth 1) loses the indirect light of the box: the script says so
    # and exits 1.
    assert os.access(PHOTONLAB, os.X_OK), "build/photonlab is missing: run scripts/setup.sh"
    scene = os.path.join(ROOT, "scenes", "cornell-box.gltf")
    extra = ["--", "--width", "24", "--spp", "8"]
    same = run_script("compare_convergence.py", PHOTONLAB, PHOTONLAB, scene, "--integrator", "path", "--seeds", "4",
                      "--tiles", "4", *extra)
    assert same.returncode == 0, same.stderr
    assert "max |z| 0.00" in same.stdout and "agree" in same.stdout
    shallow = tmp_path / "shallow"
    shallow.write_text(f'#!/bin/sh\nexec "{PHOTONLAB}" "$@" --max-depth 1\n')
    shallow.chmod(0o755)
    table = tmp_path / "table.md"
    differ = run_script("compare_convergence.py", PHOTONLAB, str(shallow), scene, "--integrator", "path", "--seeds", "4",
                        "--tiles", "4", "--markdown", str(table), *extra)
    assert differ.returncode == 1, differ.stdout + differ.stderr
    assert "DIFFER" in differ.stdout
    assert "| path | 16 |" in table.read_text()


def test_compare_bench_interleaves_two_builds_and_passes_bench_options(tmp_path):
    # scripts/compare_bench.py against two stand-in binaries: each prints a bench table whose rate
    # is its own and records the options it was given. ABBA order, the ratio new/old, and the
    # options after "--" reaching `bench`.
    def fake(name, rate):
        path = tmp_path / name
        path.write_text("#!/bin/sh\n"
                        f"echo \"$@\" >> {tmp_path / (name + '.args')}\n"
                        "echo '| scene | 1 thread |'\necho '|---|---|'\n"
                        f"echo '| box | {rate} |'\n")
        path.chmod(0o755)
        return str(path)
    old, new = fake("old", 100), fake("new", 110)
    r = subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare_bench.py"), old, new, "--rounds", "2",
                        "--", "--scene", "x.gltf"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "| box | 1 thread | 100 | 110 | 1.100 | 1.100-1.100 |" in r.stdout
    for name in ("old", "new"):
        assert (tmp_path / (name + ".args")).read_text().splitlines() == ["bench --scene x.gltf"] * 2
    assert [line.split()[1] for line in r.stderr.splitlines() if line.strip().startswith("ran")] == ["old", "new", "new", "old"]


def test_photons_in_view_table_has_every_method_and_caches_its_reference(tmp_path):
    # The shipped view only (no download): one seed, tiny times. Every method gets a row with its
    # ratio to the path tracer's mean; the chain's photons land near the view far more often than
    # uniform ones (sky.gltf's glass sphere close up: most uniform photons land elsewhere); a
    # second run reuses the cached reference.
    import photons_in_view
    cache, out = tmp_path / "cache", tmp_path / "out"
    argv = ["--views", "sky.gltf", "--width", "16", "--time", "0.5", "--reference-time", "2", "--seeds", "1",
            "--cache", str(cache), "--out", str(out)]
    assert photons_in_view.main(argv) == 0
    text = (out / "table.md").read_text()
    rows = [line for line in text.splitlines() if line.startswith("| sky.gltf")]
    assert [r.split("|")[2].strip() for r in rows] == [m[0] for m in photons_in_view.METHODS]
    assert rows[0].split("|")[5].strip() == "1.00"  # the path tracer against itself
    visible = {r.split("|")[2].strip(): float(r.split("|")[6].strip().rstrip("%")) for r in rows[1:]}
    assert visible["sppm, adaptive"] > 2 * visible["sppm, uniform"]
    assert visible["pppm, adaptive"] > 2 * visible["pppm, uniform"]
    reference = list(cache.glob("reference-*.exr"))
    assert len(reference) == 1
    stamp = reference[0].stat().st_mtime_ns
    assert photons_in_view.main(argv) == 0
    assert reference[0].stat().st_mtime_ns == stamp
