"""scripts/mitsuba_throughput.py's photonlab half, without Mitsuba: the rate and the sample count
it reads from photonlab's summary line, for a sample count and for a time budget, and the relMSE
it reads from `photonlab compare`."""
import math
import os
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import mitsuba_throughput as mt  # noqa: E402

PHOTONLAB = os.path.join(ROOT, "build", "photonlab")
BOX = os.path.join(ROOT, "scenes", "cornell-box.gltf")
needs_build = pytest.mark.skipif(not os.path.exists(PHOTONLAB), reason="needs the build")


@needs_build
def test_rate_from_a_sample_count(tmp_path):
    out = str(tmp_path / "a.exr")
    rate, seconds, spp = mt.photonlab_render(PHOTONLAB, BOX, 32, out, spp=4)
    assert spp == 4 and seconds > 0
    assert rate == pytest.approx(32 * 32 * 4 / seconds)  # the Cornell box's camera is square
    assert os.path.exists(out)


@needs_build
def test_rate_from_a_time_budget(tmp_path):
    rate, seconds, spp = mt.photonlab_render(PHOTONLAB, BOX, 16, str(tmp_path / "b.exr"), seconds=0.5)
    assert seconds == pytest.approx(0.5, abs=0.3) and spp >= 1
    assert rate == pytest.approx(16 * 16 * spp / seconds)


@needs_build
def test_relmse_is_zero_for_the_same_image_and_positive_for_another_seed(tmp_path):
    a, b = str(tmp_path / "a.exr"), str(tmp_path / "b.exr")
    mt.photonlab_render(PHOTONLAB, BOX, 16, a, spp=2, seed=1)
    mt.photonlab_render(PHOTONLAB, BOX, 16, b, spp=2, seed=2)
    assert mt.relmse(PHOTONLAB, a, a) == 0
    assert mt.relmse(PHOTONLAB, a, b) > 0


@needs_build
def test_a_failed_render_exits_with_photonlab_s_message(tmp_path):
    with pytest.raises(SystemExit, match="missing.gltf"):
        mt.photonlab_render(PHOTONLAB, str(tmp_path / "missing.gltf"), 16, str(tmp_path / "c.exr"), spp=1)


@needs_build
def test_mitsuba_samplers_photonlab_half_scores_each_sampler_and_seed(tmp_path):
    # scripts/mitsuba_samplers.py's photonlab rows, without Mitsuba: one row per (seed, sampler),
    # each the relMSE of that render against the reference; the reference scores 0 against
    # itself, and a render of another seed and sampler does not.
    import mitsuba_samplers as ms
    ref = str(tmp_path / "ref.exr")
    mt.photonlab_render(PHOTONLAB, BOX, 16, ref, spp=2, seed=1)
    rows = ms.photonlab_rows(PHOTONLAB, BOX, 16, 2, [1, 2], ["independent", "sobol"], ref, str(tmp_path))
    assert [(r[0], r[1], r[2]) for r in rows] == [("photonlab", "independent", 1), ("photonlab", "sobol", 1),
                                                   ("photonlab", "independent", 2), ("photonlab", "sobol", 2)]
    assert rows[0][3] == 0  # independent, seed 1: the reference itself
    assert all(r[3] > 0 for r in rows[1:])


def test_render_for_time_rescales_until_the_time_is_met():
    # A renderer whose rate falls as the count grows (as Mitsuba's does at hundreds of samples
    # per pixel): time = spp / (100 − spp/20) seconds. 400 spp takes 5 s, not the 4 s its rate
    # at low counts predicts, so the count is scaled by T / time until within 5% of T.
    calls = []

    def render(spp):
        calls.append(spp)
        return "image", spp / (100 - spp / 20)

    img, secs, spp = mt.render_for_time(render, 4.0, 400)
    assert img == "image" and abs(secs - 4.0) <= 0.2
    assert calls[0] == 400 and calls[1] == 320 and len(calls) <= 3
    assert spp == calls[-1]


def test_render_for_time_keeps_a_count_already_on_time_and_honours_the_sampler_s_rounding():
    once = []
    img, secs, spp = mt.render_for_time(lambda n: (once.append(n), ("image", n / 100))[1], 3.0, 300)
    assert once == [300] and spp == 300 and secs == 3.0
    # A sampler that only takes powers of four: the rescaled count is rounded its way, and a
    # count that rounds back to itself stops the loop rather than rendering it again.
    calls = []
    img, secs, spp = mt.render_for_time(lambda n: (calls.append(n), ("image", n / 100))[1], 1.0, 256,
                                        round_spp=lambda n: 4 ** max(1, round(math.log(n, 4))))
    assert calls == [256, 64] and spp == 64
