#!/usr/bin/env python3
"""Generates the shipped glTF 2.0 scenes in scenes/ (stdlib only; buffers as data URIs).

Units are radiometric and raw (see docs/pages/reference/gltf.md): emissiveFactor x KHR_materials_emissive_strength
is radiance in W/(m^2 sr); a punctual light's intensity x color is W/sr.

    python3 scripts/make_scenes.py            # rewrites scenes/*.gltf
"""
import base64
import json
import math
import os
import struct
import sys


class Gltf:
    def __init__(self):
        self.blob = bytearray()
        # Light values in W/sr, W/m², W/(m²·sr) as written (docs: reference/gltf.md, Units).
        self.doc = {"asset": {"version": "2.0", "generator": "photonlab scripts/make_scenes.py",
                              "extras": {"photonlab": {"units": "radiometric"}}},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.extensions = set()

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob),
                                        "byteLength": len(data), "target": target})
        self.blob.extend(data)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind, n):
        flat = [c for v in values for c in v] if n > 1 else list(values)
        if kind == "index":
            view = self._view(struct.pack("<%dI" % len(flat), *flat), 34963)
            acc = {"bufferView": view, "componentType": 5125, "count": len(flat), "type": "SCALAR"}
        else:
            view = self._view(struct.pack("<%df" % len(flat), *flat), 34962)
            acc = {"bufferView": view, "componentType": 5126, "count": len(values),
                   "type": {2: "VEC2", 3: "VEC3"}[n]}
            if n == 3:
                acc["min"] = [min(v[i] for v in values) for i in range(3)]
                acc["max"] = [max(v[i] for v in values) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, base=(0.8, 0.8, 0.8), metallic=0.0, roughness=1.0, emission=None,
                 glass_ior=None, double_sided=False, extras=None, dispersion=None):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0],
                                                    "metallicFactor": metallic, "roughnessFactor": roughness}}
        if double_sided:
            m["doubleSided"] = True
        if emission is not None:
            strength = max(emission)
            m["emissiveFactor"] = [e / strength for e in emission]
            if strength != 1.0:
                m.setdefault("extensions", {})["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
                self.extensions.add("KHR_materials_emissive_strength")
        if glass_ior is not None:
            ext = m.setdefault("extensions", {})
            ext["KHR_materials_transmission"] = {"transmissionFactor": 1.0}
            ext["KHR_materials_volume"] = {"thicknessFactor": 1.0}
            ext["KHR_materials_ior"] = {"ior": glass_ior}
            self.extensions.update(["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"])
            if dispersion is not None:
                ext["KHR_materials_dispersion"] = {"dispersion": dispersion}
                self.extensions.add("KHR_materials_dispersion")
        if metallic == 0.0 and glass_ior is None and not (extras and "phong" in extras):
            # A diffuse wall here is Lambertian, f = base/π: the closed forms assume it. Without
            # this marker glTF's metallic-roughness material adds its 4 % specular layer.
            extras = dict(extras or {}, bsdf="lambertian")
        if extras:
            m["extras"] = {"photonlab": extras}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, indices, material, normals=None, node_extra=None):
        attrs = {"POSITION": self._accessor(positions, "f", 3)}
        if normals is not None:
            attrs["NORMAL"] = self._accessor(normals, "f", 3)
        prim = {"attributes": attrs, "indices": self._accessor(indices, "index", 1), "material": material}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        node = {"name": name, "mesh": len(self.doc["meshes"]) - 1}
        node.update(node_extra or {})
        self.node(node)

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def camera(self, position, target, yfov, aspect=1.0):
        self.doc["cameras"] = [{"type": "perspective", "perspective": {
            "yfov": yfov, "aspectRatio": aspect, "znear": 0.01}}]
        self.node({"name": "camera", "camera": 0, "translation": list(position),
                   "rotation": look_rotation(position, target)})

    def light(self, light, position, target=None, extras=None):
        self.extensions.add("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        if extras:
            light["extras"] = {"photonlab": extras}
        lights.append(light)
        node = {"name": light.get("name", "light"), "translation": list(position),
                "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}}
        if target is not None:
            node["rotation"] = look_rotation(position, target)
        self.node(node)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(bytes(self.blob)).decode("ascii")}]
        if self.extensions:
            self.doc["extensionsUsed"] = sorted(self.extensions)
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(self.doc, f, indent=1)
        os.replace(tmp, path)


def sub(a, b): return [a[i] - b[i] for i in range(3)]
def cross(a, b): return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
def dot(a, b): return sum(a[i] * b[i] for i in range(3))
def normalize(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def look_rotation(eye, target, up=(0.0, 1.0, 0.0)):
    """Quaternion [x, y, z, w] turning local -Z towards target with +Y up (glTF cameras/lights)."""
    f = normalize(sub(target, eye))
    if abs(dot(f, up)) > 0.999:
        up = (0.0, 0.0, -1.0)
    r = normalize(cross(f, up))
    u = cross(r, f)
    z = [-f[0], -f[1], -f[2]]
    m = [[r[0], u[0], z[0]], [r[1], u[1], z[1]], [r[2], u[2], z[2]]]  # columns r, u, z
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s]
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
    return q


def quads(quad_list, scale=1.0):
    """Quads (4 corners each, counter-clockwise seen from the front) to triangles."""
    pos, idx = [], []
    for q in quad_list:
        b = len(pos)
        pos += [[c * scale for c in v] for v in q]
        idx += [b, b + 1, b + 2, b, b + 2, b + 3]
    return pos, idx


def sphere(center, radius, rings=48, segments=96, inward=False):
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
            pos.append([center[k] + radius * n[k] for k in range(3)])
            nrm.append([-x for x in n] if inward else n)
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            tris = [(a, a + 1, b), (a + 1, b + 1, b)]  # counter-clockwise seen from outside
            for t in tris:
                idx += [t[0], t[2], t[1]] if inward else list(t)
    return pos, nrm, idx


# --- the Cornell box (measured data, cornell.edu), millimetres -> metres ----------------------
MM = 0.001
WHITE, RED, GREEN = (0.725, 0.71, 0.68), (0.63, 0.065, 0.05), (0.14, 0.45, 0.091)
LIGHT_LE = (17.0, 12.0, 4.0)  # W/(m^2 sr), as in the pbrt/Mitsuba versions of the scene
FLOOR = [[552.8, 0, 0], [0, 0, 0], [0, 0, 559.2], [549.6, 0, 559.2]]
CEILING = [[556, 548.8, 0], [556, 548.8, 559.2], [0, 548.8, 559.2], [0, 548.8, 0]]
BACK = [[549.6, 0, 559.2], [0, 0, 559.2], [0, 548.8, 559.2], [556, 548.8, 559.2]]
GREEN_WALL = [[0, 0, 559.2], [0, 0, 0], [0, 548.8, 0], [0, 548.8, 559.2]]
RED_WALL = [[552.8, 0, 0], [549.6, 0, 559.2], [556, 548.8, 559.2], [556, 548.8, 0]]
# Slightly below the ceiling so the two never coincide; front face (CCW) points down.
LIGHT = [[343, 548.3, 227], [343, 548.3, 332], [213, 548.3, 332], [213, 548.3, 227]]
SHORT_BLOCK = [
    [[130, 165, 65], [82, 165, 225], [240, 165, 272], [290, 165, 114]],
    [[290, 0, 114], [290, 165, 114], [240, 165, 272], [240, 0, 272]],
    [[130, 0, 65], [130, 165, 65], [290, 165, 114], [290, 0, 114]],
    [[82, 0, 225], [82, 165, 225], [130, 165, 65], [130, 0, 65]],
    [[240, 0, 272], [240, 165, 272], [82, 165, 225], [82, 0, 225]]]
TALL_BLOCK = [
    [[423, 330, 247], [265, 330, 296], [314, 330, 456], [472, 330, 406]],
    [[423, 0, 247], [423, 330, 247], [472, 330, 406], [472, 0, 406]],
    [[472, 0, 406], [472, 330, 406], [314, 330, 456], [314, 0, 456]],
    [[314, 0, 456], [314, 330, 456], [265, 330, 296], [265, 0, 296]],
    [[265, 0, 296], [265, 330, 296], [423, 330, 247], [423, 0, 247]]]


def cornell_shell(g):
    white = g.material("white", WHITE)
    g.mesh("walls", *quads([FLOOR, CEILING, BACK], MM), white)
    g.mesh("red wall", *quads([RED_WALL], MM), g.material("red", RED))
    g.mesh("green wall", *quads([GREEN_WALL], MM), g.material("green", GREEN))
    g.mesh("light", *quads([LIGHT], MM), g.material("light", (0, 0, 0), emission=LIGHT_LE))
    # Camera of the measured scene: 35 mm lens on a 25 mm film -> yfov = 2 atan(12.5/35).
    g.camera([0.278, 0.273, -0.800], [0.278, 0.273, 0.0], 2 * math.atan(12.5 / 35.0))
    return white


def cornell_box():
    g = Gltf()
    white = cornell_shell(g)
    g.mesh("short block", *quads(SHORT_BLOCK, MM), white)
    g.mesh("tall block", *quads(TALL_BLOCK, MM), white)
    return g


def cornell_spheres():
    g = Gltf()
    cornell_shell(g)
    r = 0.1
    mirror = g.material("mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)
    glass = g.material("glass", (1, 1, 1), glass_ior=1.5)
    p, n, i = sphere([0.380, r, 0.360], r)
    g.mesh("mirror sphere", p, i, mirror, normals=n)
    p, n, i = sphere([0.170, r, 0.170], r)
    g.mesh("glass sphere", p, i, glass, normals=n)
    return g


def glass_caustic():
    g = Gltf()
    floor = g.material("floor", (0.8, 0.8, 0.8))
    g.mesh("floor", *quads([[[-4, 0, -4], [-4, 0, 4], [4, 0, 4], [4, 0, -4]]]), floor)
    g.mesh("back wall", *quads([[[-4, 0, -2], [4, 0, -2], [4, 3, -2], [-4, 3, -2]]]), floor)
    p, n, i = sphere([0.0, 0.5, 0.0], 0.5)
    g.mesh("glass sphere", p, i, g.material("glass", (1, 1, 1), glass_ior=1.5), normals=n)
    # A small spot light up and to the left, aimed at the sphere: the caustic lands on the
    # floor to the right, inside the sphere's shadow.
    g.light({"name": "spot", "type": "spot", "color": [1, 1, 1], "intensity": 60.0,
             "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.35}},
            [-1.6, 3.0, 0.0], [0.0, 0.5, 0.0])
    g.camera([0.6, 2.0, 3.6], [0.6, 0.3, 0.0], 0.75, aspect=4 / 3)
    return g


def prism():
    """White light through a dispersive glass prism onto a white wall (issue: spectral mode).
    Equilateral prism (apex 60°) with n_d = 1.6 and Abbe number V_d = 20 (dispersion = 20/V_d = 1),
    its axis along z. The spot light's beam meets the left face at the angle of minimum
    deviation for the d line, δ = 2·asin(n·sin 30°) − 60° = 46.3°: inside, the beam runs parallel
    to the base and leaves 23.1° below the horizontal towards the wall at x = 2."""
    g = Gltf()
    white = g.material("white", (0.8, 0.8, 0.8))
    grey = g.material("grey", (0.3, 0.3, 0.3))
    g.mesh("floor", *quads([[[-3, 0, -1.5], [-3, 0, 2], [2, 0, 2], [2, 0, -1.5]]]), grey)
    g.mesh("wall", *quads([[[2, 0, -1.5], [2, 0, 2], [2, 2, 2], [2, 2, -1.5]]]), white)
    g.mesh("back wall", *quads([[[-3, 0, -1.5], [2, 0, -1.5], [2, 2, -1.5], [-3, 2, -1.5]]]), grey)
    s, y0, zh = 0.6, 0.8, 0.4
    h = s * math.sqrt(3) / 2
    a, b, c = [-s / 2, y0], [s / 2, y0], [0.0, y0 + h]  # base left, base right, apex (x, y)
    corners = [[p[0], p[1], z] for z in (zh, -zh) for p in (a, b, c)]  # 0-2 front (z+), 3-5 back
    A, B, C, A2, B2, C2 = range(6)
    tris = [A, B, C, A2, C2, B2,            # front and back caps (outward: +z, -z)
            A, C, C2, A, C2, A2,            # left face
            B, B2, C2, B, C2, C,            # right face
            A, A2, B2, A, B2, B]            # base (outward: -y)
    glass = g.material("flint glass", (1, 1, 1), glass_ior=1.6, dispersion=1.0)
    g.mesh("prism", corners, tris, glass)
    # The beam: aimed at the left face's centre along 23.13° above the horizontal.
    theta = math.radians((46.26 + 60.0) / 2 - 30.0)
    face = [(a[0] + c[0]) / 2, (a[1] + c[1]) / 2, 0.0]
    d = [math.cos(theta), math.sin(theta), 0.0]
    pos = [face[i] - 2.0 * d[i] for i in range(3)]
    g.light({"name": "beam", "type": "spot", "color": [1, 1, 1], "intensity": 4000.0,
             "spot": {"innerConeAngle": 0.01, "outerConeAngle": 0.015}}, pos, face)
    # A dim fill light above, so the room and the prism are not black.
    g.light({"name": "fill", "type": "point", "color": [1, 1, 1], "intensity": 0.4}, [0.5, 1.9, 1.2])
    g.camera([1.0, 0.8, 1.5], [1.5, 0.45, 0.0], 0.75, aspect=4 / 3)
    return g


def furnace(Le=1.0, albedo=0.5):
    """Closed diffuse sphere, every point emitting Le with albedo rho: L = Le / (1 - rho)."""
    g = Gltf()
    p, n, i = sphere([0, 0, 0], 1.0, rings=24, segments=48, inward=True)
    m = g.material("furnace", (albedo,) * 3, emission=(Le,) * 3)
    g.mesh("furnace", p, i, m, normals=n)
    g.camera([0, 0, 0], [0, 0, -1], 1.2)
    return g


# SmallVCM's Cornell box (Davidovič & Georgiev; scene.hxx LoadCornellBox), for the side-by-side
# comparison of the bidirectional methods: the glossy floor (modified Phong, kd 0.1, ks 0.7,
# exponent 90), blue back wall, a mirror and a glass (n = 1.6) sphere of radius 0.5. SmallVCM is
# z-up; glTF is y-up: (x, y, z) -> (x, z, -y).
def _svcm(p):
    return [p[0], p[2], -p[1]]


SVCM_BOX = [(-1.27029, 1.30455, -1.28002), (1.28975, 1.30455, -1.28002), (1.28975, 1.30455, 1.28002),
            (-1.27029, 1.30455, 1.28002), (-1.27029, -1.25549, -1.28002), (1.28975, -1.25549, -1.28002),
            (1.28975, -1.25549, 1.28002), (-1.27029, -1.25549, 1.28002)]
SVCM_LIGHT_BOX = [(-0.25, 0.25, 1.26002), (0.25, 0.25, 1.26002), (0.25, 0.25, 1.28002), (-0.25, 0.25, 1.28002),
                  (-0.25, -0.25, 1.26002), (0.25, -0.25, 1.26002), (0.25, -0.25, 1.28002), (-0.25, -0.25, 1.28002)]


def _triangles(g, name, corners, tris, material):
    positions, indices = [], []
    for t in tris:
        for k in t:
            indices.append(len(positions))
            positions.append(_svcm(corners[k]))
    g.mesh(name, positions, indices, material)


def smallvcm_box(light):
    """SmallVCM's g_SceneConfigs[0] (light="sun": glossy floor, both small spheres, the
    directional "sun", with the unlit light box under the ceiling) or [2] (light="point": the
    same lit by a 70 W point light, without the light box)."""
    g = Gltf()
    cb = SVCM_BOX
    floor = g.material("glossy floor", (0.8, 0.8, 0.8),
                       extras={"phong": {"kd": [0.1, 0.1, 0.1], "ks": [0.7, 0.7, 0.7], "exponent": 90.0}})
    white = g.material("white", (0.803922, 0.803922, 0.803922))
    _triangles(g, "floor", cb, [(0, 4, 5), (5, 1, 0)], floor)
    _triangles(g, "back wall", cb, [(0, 1, 2), (2, 3, 0)], g.material("blue", (0.156863, 0.172549, 0.803922)))
    _triangles(g, "ceiling", cb, [(2, 6, 7), (7, 3, 2)], white)
    _triangles(g, "left wall", cb, [(3, 7, 4), (4, 0, 3)], g.material("green", (0.156863, 0.803922, 0.172549)))
    _triangles(g, "right wall", cb, [(1, 5, 6), (6, 2, 1)], g.material("red", (0.803922, 0.152941, 0.152941)))
    radius = 0.5
    left = [(cb[0][i] + cb[4][i]) / 2 for i in range(3)]
    right = [(cb[1][i] + cb[5][i]) / 2 for i in range(3)]
    xlen = right[0] - left[0]
    mirror_centre = [left[0] + 2 * xlen / 7, left[1], left[2] + radius]
    glass_centre = [right[0] - 2 * xlen / 7, right[1], right[2] + radius]
    p, n, i = sphere(_svcm(mirror_centre), radius)
    g.mesh("mirror sphere", p, i, g.material("mirror", (1, 1, 1), metallic=1.0, roughness=0.0), normals=n)
    p, n, i = sphere(_svcm(glass_centre), radius)
    g.mesh("glass sphere", p, i, g.material("glass", (1, 1, 1), glass_ior=1.6), normals=n)
    if light == "sun":
        _triangles(g, "light box", SVCM_LIGHT_BOX,
                   [(0, 2, 1), (2, 0, 3), (3, 4, 7), (4, 3, 0), (1, 6, 5), (6, 1, 2), (4, 5, 6), (6, 7, 4),
                    (0, 5, 4), (5, 0, 1)], white)
        d = _svcm((-1.0, 1.5, -1.0))  # the direction the light travels
        g.light({"name": "sun", "type": "directional", "color": [1.0, 0.4, 0.0], "intensity": 10.0},
                [0.0, 2.0, 0.0], [d[0], 2.0 + d[1], d[2]])
    else:
        g.light({"name": "point", "type": "point", "color": [1, 1, 1], "intensity": 70.0 / (4 * math.pi)},
                _svcm((0.0, -0.5, 1.0)))
    eye = _svcm((-0.0439815, -4.12529, 0.222539))
    forward = _svcm((0.00688625, 0.998505, -0.0542161))
    g.camera(eye, [eye[i] + forward[i] for i in range(3)], math.radians(45.0))
    return g


def box(lo, hi, rotate_y=0.0, pivot=None):
    """An axis-aligned box [lo, hi], turned by rotate_y radians about the vertical through pivot:
    six quads, counter-clockwise seen from outside."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [[[x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0]],   # -x
             [[x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]],   # +x
             [[x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]],   # -y
             [[x0, y1, z0], [x0, y1, z1], [x1, y1, z1], [x1, y1, z0]],   # +y
             [[x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [x1, y0, z0]],   # -z
             [[x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]]   # +z
    if rotate_y:
        px, _, pz = pivot
        c, s = math.cos(rotate_y), math.sin(rotate_y)
        faces = [[[px + c * (v[0] - px) + s * (v[2] - pz), v[1], pz - s * (v[0] - px) + c * (v[2] - pz)] for v in f]
                 for f in faces]
    return faces


def door():
    """Veach's door left ajar (Veach 1997, fig. 10.3): a room lit only through a door opened by
    12 degrees into the next room, whose ceiling light the camera cannot see. Light reaches the
    camera's room after at least two bounces, through a gap a few centimetres wide: where a
    path tracer's cosine-weighted directions rarely go, and a guide learns to."""
    g = Gltf()
    wall = g.material("wall", (0.7, 0.7, 0.7))
    floor = g.material("floor", (0.5, 0.45, 0.4))
    # The camera's room: x in [0, 4], y in [0, 2.6], z in [0, 4]; the light's room: z in [4.1, 7].
    g.mesh("floor", *quads([[[0, 0, 0], [0, 0, 7], [4, 0, 7], [4, 0, 0]]]), floor)
    g.mesh("room", *quads([[[0, 2.6, 0], [4, 2.6, 0], [4, 2.6, 7], [0, 2.6, 7]],    # ceiling
                           [[0, 0, 0], [4, 0, 0], [4, 2.6, 0], [0, 2.6, 0]],        # front
                           [[0, 0, 7], [0, 2.6, 7], [4, 2.6, 7], [4, 0, 7]],        # back
                           [[0, 0, 0], [0, 2.6, 0], [0, 2.6, 7], [0, 0, 7]],        # left
                           [[4, 0, 0], [4, 0, 7], [4, 2.6, 7], [4, 2.6, 0]]]), wall)  # right
    # The wall between the rooms, 10 cm thick, with a doorway x in [1.5, 2.4], y in [0, 2].
    partition = box([0, 0, 4.0], [1.5, 2.6, 4.1]) + box([2.4, 0, 4.0], [4, 2.6, 4.1]) + box([1.5, 2.0, 4.0], [2.4, 2.6, 4.1])
    g.mesh("partition", *quads(partition), wall)
    # The door, 4 cm thick, hinged on the doorway's left post at the light room's face, opened
    # into the light room by 12 degrees: its free edge leaves a wedge about 19 cm deep.
    g.mesh("door", *quads(box([1.5, 0.0, 4.1], [2.39, 1.99, 4.14], rotate_y=-math.radians(12), pivot=[1.5, 0, 4.1])),
           g.material("door", (0.6, 0.5, 0.4)))
    # Furniture in the camera's room, so that the indirect light has shapes to shade.
    g.mesh("table", *quads(box([2.6, 0, 1.8], [3.5, 0.75, 2.8])), g.material("table", (0.6, 0.6, 0.6)))
    g.mesh("cabinet", *quads(box([0.2, 0, 2.6], [0.8, 1.6, 3.6])), wall)
    # The light: 1 m x 0.5 m on the light room's ceiling, near its far wall, facing down.
    g.mesh("light", *quads([[[1.2, 2.59, 6.2], [2.2, 2.59, 6.2], [2.2, 2.59, 6.7], [1.2, 2.59, 6.7]]]),
           g.material("light", (0, 0, 0), emission=(60.0, 60.0, 60.0)))
    g.camera([3.6, 1.5, 0.3], [1.9, 0.9, 4.0], math.radians(60.0))
    return g


def sky():
    """Three spheres on a floor under a sky and nothing else (the environment light): diffuse,
    mirror and glass, radius 0.5, on a 12 m square floor. The sky is a constant blue-white
    (extras.photonlab.environment); --env replaces it, with a map for instance."""
    g = Gltf()
    floor = g.material("floor", (0.5, 0.5, 0.5))
    g.mesh("floor", *quads([[[-6, 0, -6], [-6, 0, 6], [6, 0, 6], [6, 0, -6]]]), floor)
    for name, x, m in (("diffuse sphere", -1.2, g.material("diffuse", (0.8, 0.3, 0.2))),
                       ("mirror sphere", 0.0, g.material("mirror", (0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)),
                       ("glass sphere", 1.2, g.material("glass", (1, 1, 1), glass_ior=1.5))):
        p, n, i = sphere([x, 0.5, 0.0], 0.5)
        g.mesh(name, p, i, m, normals=n)
    g.doc["extras"] = {"photonlab": {"environment": {"radiance": [0.8, 0.9, 1.0]}}}
    g.camera([0.0, 1.6, 4.2], [0.0, 0.45, 0.0], 0.6, aspect=3 / 2)
    return g


SCENES = {"cornell-box": cornell_box, "cornell-spheres": cornell_spheres,
          "glass-caustic": glass_caustic, "furnace": furnace, "prism": prism,
          "smallvcm-sun": lambda: smallvcm_box("sun"), "smallvcm-point": lambda: smallvcm_box("point"),
          "door": door, "sky": sky}

if __name__ == "__main__":
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
    for name in sys.argv[1:] or SCENES:
        SCENES[name]().write(os.path.join(out, name + ".gltf"))
        print("wrote scenes/%s.gltf" % name)
