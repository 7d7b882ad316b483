"""The scene generator: shipped scenes are exactly what it writes, and its look-at rotation
turns a glTF camera's -Z towards the target."""
import importlib.util
import json
import math
import os
import random

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
spec = importlib.util.spec_from_file_location("make_scenes", os.path.join(ROOT, "scripts", "make_scenes.py"))
make_scenes = importlib.util.module_from_spec(spec)
spec.loader.exec_module(make_scenes)


def rotate(q, v):
    x, y, z, w = q
    u = [x, y, z]
    t = [2 * c for c in make_scenes.cross(u, v)]
    return [v[i] + w * t[i] + make_scenes.cross(u, t)[i] for i in range(3)]


def test_look_rotation_aims_minus_z_at_target_with_y_up():
    rng = random.Random(1)
    for _ in range(200):
        eye = [rng.uniform(-5, 5) for _ in range(3)]
        target = [rng.uniform(-5, 5) for _ in range(3)]
        q = make_scenes.look_rotation(eye, target)
        assert abs(sum(c * c for c in q) - 1) < 1e-9
        forward = rotate(q, [0, 0, -1])
        expected = make_scenes.normalize(make_scenes.sub(target, eye))
        assert all(abs(forward[i] - expected[i]) < 1e-9 for i in range(3))
        up = rotate(q, [0, 1, 0])
        if abs(expected[1]) < 0.99:
            assert up[1] > 0  # the image is not upside down


def test_shipped_scenes_match_the_generator(tmp_path):
    for name, build in make_scenes.SCENES.items():
        out = tmp_path / (name + ".gltf")
        build().write(str(out))
        with open(os.path.join(ROOT, "scenes", name + ".gltf")) as f:
            shipped = json.load(f)
        assert json.loads(out.read_text()) == shipped, name + ".gltf is stale: run scripts/make_scenes.py"


def test_cornell_light_faces_down_and_has_the_classic_radiance():
    g = make_scenes.cornell_box()
    light = [m for m in g.doc["materials"] if m["name"] == "light"][0]
    strength = light["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
    assert [round(c * strength, 6) for c in light["emissiveFactor"]] == [17.0, 12.0, 4.0]
    p = make_scenes.LIGHT
    n = make_scenes.cross(make_scenes.sub(p[1], p[0]), make_scenes.sub(p[2], p[0]))
    assert n[1] < 0 and abs(n[0]) < 1e-9 and abs(n[2]) < 1e-9
    assert math.isclose(make_scenes.look_rotation([0, 0, 0], [0, 0, 1])[1], 1.0, abs_tol=1e-9)
