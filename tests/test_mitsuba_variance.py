"""scripts/mitsuba_variance.py's conversion of photonlab scenes for Mitsuba 3, without Mitsuba: the
glTF reader against `photonlab info`, the camera's basis, the material mapping, and the PLY
writer read back by hand."""
import os
import re
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import mitsuba_variance as mv  # noqa: E402

PHOTONLAB = os.path.join(ROOT, "build", "photonlab")
SPHERES = os.path.join(ROOT, "scenes", "cornell-spheres.gltf")


def info(scene):
    return subprocess.run([PHOTONLAB, "info", scene], check=True, capture_output=True, text=True).stdout


@pytest.mark.skipif(not os.path.exists(PHOTONLAB), reason="needs the build")
def test_reader_sees_the_triangles_and_camera_photonlab_sees():
    meshes, materials, camera = mv.read_gltf(SPHERES)
    text = info(SPHERES)
    assert sum(len(i) for _, _, i, _ in meshes) == int(re.search(r"triangles: (\d+)", text).group(1))
    origin, forward, up, yfov = camera
    m = re.search(r"camera used by default: .*position \[([^\]]*)\], forward \[([^\]]*)\], yfov ([0-9.]+)", text)
    assert np.allclose(origin, [float(v) for v in m.group(1).split(",")], atol=1e-6)
    assert np.allclose(forward, [float(v) for v in m.group(2).split(",")], atol=1e-5)
    assert yfov == pytest.approx(float(m.group(3)), rel=1e-5)
    assert np.dot(forward, up) == pytest.approx(0.0, abs=1e-6) and np.linalg.norm(up) == pytest.approx(1.0)
    # Smooth spheres keep their normals; the box's quads have none.
    assert sum(n is not None for _, n, _, _ in meshes) == 2


def test_materials_map_to_their_mitsuba_counterparts():
    _, materials, _ = mv.read_gltf(SPHERES)
    kinds = {m["name"]: mv.mitsuba_bsdf(m)["type"] for m in materials if "emissiveFactor" not in m}
    assert kinds["white"] == "diffuse" and kinds["mirror"] == "conductor" and kinds["glass"] == "dielectric"
    assert mv.mitsuba_bsdf(next(m for m in materials if m["name"] == "red"))["reflectance"]["value"] == [0.63, 0.065, 0.05]
    with pytest.raises(SystemExit, match="no Mitsuba counterpart"):
        mv.mitsuba_bsdf({"name": "rough", "pbrMetallicRoughness": {"metallicFactor": 0.5, "roughnessFactor": 0.5}})


def test_ply_writer_round_trip(tmp_path):
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    n = np.array([[0, 0, 1]] * 3, np.float32)
    f = np.array([[0, 1, 2]], np.uint32)
    path = str(tmp_path / "t.ply")
    mv.write_ply(path, p, n, f)
    data = open(path, "rb").read()
    header, body = data.split(b"end_header\n")
    assert b"element vertex 3" in header and b"property float nz" in header and b"element face 1" in header
    v = np.frombuffer(body[: 3 * 6 * 4], "<f4").reshape(3, 6)
    assert np.array_equal(v[:, :3], p) and np.array_equal(v[:, 3:], n)
    assert body[72] == 3 and list(np.frombuffer(body[73:85], "<i4")) == [0, 1, 2]
    assert len(body) == 85


def test_markdown_table_gives_each_depth_s_variance_ratio_and_marks_black_pixels():
    # The table results_pages.py puts on the Mitsuba page: photonlab's variance over Mitsuba's per
    # pixel set; a set with no variance in Mitsuba's image (the indirect pixels at depth 1) is black.
    rows = [{"depth": 1, "photonlab": {"all": (0.5, 0.02), "indirect": (0.0, 0.0)},
             "mitsuba": {"all": (0.5, 0.04), "indirect": (0.0, 0.0)}},
            {"depth": 64, "photonlab": {"all": (0.7, 0.03), "indirect": (0.1, 0.011)},
             "mitsuba": {"all": (0.7, 0.03), "indirect": (0.1, 0.01)}}]
    lines = mv.markdown_table(rows).splitlines()
    assert lines[0].startswith("| max depth |") and lines[1] == "|---|---|---|"
    assert lines[2] == "| 1 | 0.500 | (black) |"
    assert lines[3] == "| 64 | 1.000 | 1.100 |"
