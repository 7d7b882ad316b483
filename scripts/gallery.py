#!/usr/bin/env python3
"""Renders Khronos glTF sample models as shipped: the documentation's gallery (docs/pages/results/gallery.md).

Each model is taken from --source, a folder laid out as Khronos' glTF-Sample-Assets repository's
Models/ (Models/NAME/glTF-Binary/NAME.glb, or Models/NAME/glTF/NAME.gltf with its files), or a URL
of that layout (by default the repository itself on GitHub), in which case the files are
downloaded into --cache first. Nothing is committed but the images and the table. Each model is
path traced with no option beyond its size and time (its own camera or the automatic one, its
own lights or the default sky), except where the table says; the warnings photonlab printed are
counted in the table.

    /usr/bin/python3 scripts/gallery.py --source ~/glTF-Sample-Assets/Models --out docs/pages/images/gallery
    /usr/bin/python3 scripts/gallery.py --out docs/pages/images/gallery          # downloads the models first
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import urllib.parse
import urllib.request

KHRONOS = "https://raw.githubusercontent.com/KhronosGroup/glTF-Sample-Assets/main/Models"

# (model, extra render options, what it shows)
MODELS = [
    ("DamagedHelmet", [], "metallic-roughness, normal and emissive textures; automatic camera, default sky"),
    ("ToyCar", [], "its own camera (the first of 8); transmission; clearcoat and sheen ignored (warned)"),
    ("WaterBottle", [], "metallic-roughness and normal textures"),
    ("CesiumMilkTruck", [], "base-colour textures, a node hierarchy"),
    ("GlassVaseFlowers", [], "refracting glass (transmission + volume), alpha-masked leaves"),
    ("GlassHurricaneCandleHolder", [], "absorbing glass (KHR_materials_volume attenuation)"),
    ("TransmissionRoughnessTest", [], "thin-walled transmission, roughness 0 to 1"),
    ("AttenuationTest", [], "attenuationColor and attenuationDistance, row by row"),
    ("VertexColorTest", [], "COLOR_0 vertex colours"),
    ("AlphaBlendModeTest", [], "alphaMode OPAQUE, MASK, BLEND"),
    ("SimpleInstancing", [], "EXT_mesh_gpu_instancing: 125 cubes, one mesh stored"),
    ("LightsPunctualLamp", ["--exposure", "4"], "KHR_lights_punctual spot and point lights (candela / 683), shown at +4 EV"),
]


def local_model(root, name):
    """The model's file in a Models/ folder: the .glb if there is one, else the .gltf."""
    for sub, ext in (("glTF-Binary", ".glb"), ("glTF", ".gltf")):
        path = os.path.join(root, name, sub, name + ext)
        if os.path.isfile(path):
            return path
    return None


def download(url, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".part"
    with urllib.request.urlopen(url, timeout=120) as r, open(tmp, "wb") as f:
        shutil.copyfileobj(r, f)
    os.replace(tmp, path)


def fetch_model(base, cache, name):
    """Downloads a model from a Models/-layout URL into cache: the .glb, or the .gltf and every
    external file it names. Returns its local path."""
    for sub, ext in (("glTF-Binary", ".glb"), ("glTF", ".gltf")):
        rel = f"{name}/{sub}/{name}{ext}"
        path = os.path.join(cache, rel)
        if not os.path.isfile(path):
            try:
                download(f"{base}/{urllib.parse.quote(rel)}", path)
            except OSError:
                continue
        if ext == ".gltf":
            doc = json.load(open(path, encoding="utf-8"))
            for item in doc.get("buffers", []) + doc.get("images", []):
                uri = item.get("uri", "")
                if uri and not uri.startswith("data:"):
                    target = os.path.join(os.path.dirname(path), urllib.parse.unquote(uri))
                    if not os.path.isfile(target):
                        quoted = urllib.parse.quote(urllib.parse.unquote(uri))
                        download(f"{base}/{urllib.parse.quote(name + '/' + sub)}/{quoted}", target)
        return path
    return None


def render(photonlab, model, out_png, width, spp, seconds, extra):
    """photonlab render; returns (ok, warning lines, error line)."""
    cmd = [photonlab, "render", model, "--integrator", "path", "--width", str(width), "--spp", str(spp),
           "--time", str(seconds), "-q", "-o", out_png] + extra
    r = subprocess.run(cmd, capture_output=True, text=True)
    warnings = [l for l in r.stderr.splitlines() if l.startswith("warning:")]
    error = next((l for l in r.stderr.splitlines() if l.startswith("photonlab:")), "")
    return r.returncode == 0, warnings, error


def main(argv=None):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--source", default=KHRONOS, help="a Models/ folder, or a URL of that layout (default: Khronos' on GitHub)")
    p.add_argument("--cache", default=os.path.join(root, "build", "gallery-models"), help="where downloads go")
    p.add_argument("--out", default=os.path.join(root, "docs", "gallery"), help="the images and gallery.md")
    p.add_argument("--photonlab", default=os.path.join(root, "build", "photonlab"))
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--time", type=float, default=45.0, help="seconds per model (the render stops at --spp or here)")
    p.add_argument("--models", help="comma-separated subset of the list")
    args = p.parse_args(argv)
    remote = "://" in args.source
    wanted = set(args.models.split(",")) if args.models else None
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for name, extra, shows in MODELS:
        if wanted and name not in wanted:
            continue
        path = fetch_model(args.source, args.cache, name) if remote else local_model(args.source, name)
        if not path:
            print(f"gallery: {name}: not found in {args.source}", file=sys.stderr)
            continue
        png = os.path.join(args.out, name + ".png")
        ok, warnings, error = render(args.photonlab, path, png, args.width, args.spp, args.time, extra)
        print(f"gallery: {name}: {'rendered' if ok else error} ({len(warnings)} warnings)", file=sys.stderr)
        options = " ".join(extra) if extra else "as shipped"
        cell = f"![{name}]({name}.png)" if ok else f"failed: {error}"
        rows.append(f"| {cell} | {name} ({os.path.basename(path)}) | {shows} | {options} | {len(warnings)} |")
    table = ["| render | model | what it shows | options | warnings |", "|---|---|---|---|---|"] + rows
    with open(os.path.join(args.out, "gallery.md.part"), "w", encoding="utf-8") as f:
        f.write("\n".join(table) + "\n")
    os.replace(os.path.join(args.out, "gallery.md.part"), os.path.join(args.out, "gallery.md"))
    print("\n".join(table))
    return 0 if rows else 1


if __name__ == "__main__":
    sys.exit(main())
