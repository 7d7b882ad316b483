#!/usr/bin/env python3
"""Renders Khronos glTF sample models as shipped, with photonlab's defaults only: the
documentation's gallery (docs/pages/results/gallery.md).

Each model is taken from --source, a folder laid out as Khronos' glTF-Sample-Assets repository's
Models/ (Models/NAME/glTF-Binary/NAME.glb, or Models/NAME/glTF/NAME.gltf with its files), or a URL
of that layout (by default the repository itself on GitHub), in which case the files are
downloaded into --cache first. Each is path traced with no option beyond its size and time (its
own camera or the automatic one, its own lights or the default sky, the automatic exposure and
the default tone curve); the warnings photonlab printed are counted. The PNGs go to --out with a
table (gallery.md), or with --page the results page instead; with --exr the linear images are
kept there (for `photonlab tonemap`). Nothing of the models is committed.

    /usr/bin/python3 scripts/gallery.py --source ~/glTF-Sample-Assets/Models --out docs/pages/images/gallery \
        --page docs/pages/results/gallery.md
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

# (model, what it shows, what the render shows: written after looking at it)
MODELS = [
    ("DamagedHelmet", "metallic-roughness, normal and emissive textures; automatic camera, default sky",
     "the helmet whole on the overcast sky, its top lit and its underside in shade; the visor's cyan emissive panels glow, the scratched metal reflects the bright sky above and the ground below"),
    ("ToyCar", "its own camera (the first of 8); transmission; clearcoat on the body, sheen on the cloth",
     "the green car on its red velvet from the file's camera, which cuts the tail fins; the coat's highlights along the bodywork, the velvet lighter on its folds where the sheen catches the sky; clear windows; the sky behind bright"),
    ("SheenChair", "KHR_materials_sheen velvet (sheen roughness 0.8) over textured fabric; wooden legs",
     "the orange velvet chair whole, seat and back lighter toward their edges where the sheen rises at grazing angles, the underside of the seat in shade; dark wooden legs"),
    ("ClearCoatCarPaint", "KHR_materials_clearcoat (factor 1, roughness 0) over a red paint with a normal map",
     "a red sphere, light over its upper half where the coat reflects the bright sky and dark below where it reflects the ground, the paint's flake pattern visible through the coat"),
    ("WaterBottle", "metallic-roughness and normal textures",
     "the bottle whole: yellow body, dark red cap, the logo and the black holder legible"),
    ("CesiumMilkTruck", "base-colour textures, a node hierarchy",
     "the truck whole; its white roof bright and its sides grey under the overcast sky, so the body stands apart from the background"),
    ("GlassVaseFlowers", "refracting glass (transmission + volume), alpha-masked leaves",
     "leaves and petals cut out by their masks; the vases refract the stems"),
    ("GlassHurricaneCandleHolder", "absorbing glass (KHR_materials_volume attenuation)",
     "the blue-tinted glass deepest where it is thickest, the candle seen through it"),
    ("TransmissionRoughnessTest", "thin-walled transmission, roughness 0 to 1",
     "the test board small in the automatic view; the panes blur the pattern behind them more as roughness grows"),
    ("AttenuationTest", "attenuationColor and attenuationDistance, row by row",
     "the blue blocks darker the thicker they are, row by row"),
    ("VertexColorTest", "COLOR_0 vertex colours", "the red, green and blue checks and their labels read"),
    ("AlphaBlendModeTest", "alphaMode OPAQUE, MASK, BLEND", "the blended and masked strips show the marble board behind them"),
    ("SimpleInstancing", "EXT_mesh_gpu_instancing: 125 cubes, one mesh stored", "the 125 grey cubes, scattered and rotated, their tops lighter than their sides"),
    ("LightsPunctualLamp", "KHR_lights_punctual spot and point lights (candela / 683)",
     "the lamp lit by its own bulb on black, exposed for the lit parts: the glass shade clips to white"),
    ("EmissiveStrengthTest", "KHR_materials_emissive_strength on emissive cubes",
     "the cubes glow cyan inside their grey boxes and light the walls around them"),
    ("UnlitTest", "KHR_materials_unlit (its base colour emitted)", "the two flat-shaded shapes in their base colours, orange and blue"),
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


def render(photonlab, model, out_png, width, spp, seconds, exr=None):
    """photonlab render; returns (ok, warning lines, error line)."""
    cmd = [photonlab, "render", model, "--integrator", "path", "--width", str(width), "--spp", str(spp),
           "--time", str(seconds), "-q", "-o", out_png] + (["-o", exr] if exr else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    warnings = [l for l in r.stderr.splitlines() if l.startswith("warning:")]
    error = next((l for l in r.stderr.splitlines() if l.startswith("photonlab:")), "")
    return r.returncode == 0, warnings, error


def main(argv=None):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--source", default=KHRONOS, help="a Models/ folder, or a URL of that layout (default: Khronos' on GitHub)")
    p.add_argument("--cache", default=os.path.join(root, "build", "gallery-models"), help="where downloads go")
    p.add_argument("--out", default=os.path.join(root, "docs", "pages", "images", "gallery"), help="the images and gallery.md")
    p.add_argument("--photonlab", default=os.path.join(root, "build", "photonlab"))
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--time", type=float, default=45.0, help="seconds per model (the render stops at --spp or here)")
    p.add_argument("--models", help="comma-separated subset of the list")
    p.add_argument("--page", help="also write the results page here (Markdown, images linked relative to it)")
    p.add_argument("--exr", help="keep each model's linear image in this folder")
    args = p.parse_args(argv)
    remote = "://" in args.source
    wanted = set(args.models.split(",")) if args.models else None
    os.makedirs(args.out, exist_ok=True)
    rows, shown = [], []
    if args.exr:
        os.makedirs(args.exr, exist_ok=True)
    for name, shows, looks in MODELS:
        if wanted and name not in wanted:
            continue
        path = fetch_model(args.source, args.cache, name) if remote else local_model(args.source, name)
        if not path:
            print(f"gallery: {name}: not found in {args.source}", file=sys.stderr)
            continue
        png = os.path.join(args.out, name + ".png")
        exr = os.path.join(args.exr, name + ".exr") if args.exr else None
        ok, warnings, error = render(args.photonlab, path, png, args.width, args.spp, args.time, exr)
        print(f"gallery: {name}: {'rendered' if ok else error} ({len(warnings)} warnings)", file=sys.stderr)
        cell = f"![{name}]({name}.png)" if ok else f"failed: {error}"
        rows.append(f"| {cell} | {name} ({os.path.basename(path)}) | {shows} | {len(warnings)} |")
        shown.append((name, os.path.basename(path), shows, looks if ok else f"failed: {error}", len(warnings), ok))
    table = ["| render | model | what it shows | warnings |", "|---|---|---|---|"] + rows
    if not args.page:  # the table beside the images; with --page, the page instead
        with open(os.path.join(args.out, "gallery.md.part"), "w", encoding="utf-8") as f:
            f.write("\n".join(table) + "\n")
        os.replace(os.path.join(args.out, "gallery.md.part"), os.path.join(args.out, "gallery.md"))
    print("\n".join(table))
    if args.page and shown:
        write_page(args.page, args.out, shown, args)
    return 0 if rows else 1


def write_page(page, images, shown, args):
    """The results page: the command, the images, and per model what it shows and what the
    render shows."""
    rel = os.path.relpath(images, os.path.dirname(os.path.abspath(page)))
    lines = ["# Gallery", "",
             f"**Khronos sample models as shipped, with the defaults.** `scripts/gallery.py` renders each with "
             f"the path tracer at {args.width} pixels wide, {args.time:g} s or {args.spp} spp, and no option "
             "at all: the model's own camera or the automatic view, its own lights or the default sky, the "
             "automatic exposure and the default tone curve. The warnings column counts what photonlab said "
             "it ignored or supplied (camera, sky, occlusion textures, ...). The models come "
             "from a folder laid out as Khronos' glTF-Sample-Assets `Models/`, or are downloaded from that "
             "repository; nothing of them is committed.", "",
             "```sh",
             f"/usr/bin/python3 scripts/gallery.py --source PATH/glTF-Sample-Assets/Models --width {args.width} "
             f"--time {args.time:g} --out docs/pages/images/gallery --page docs/pages/results/gallery.md",
             "```", "", "<p>"]
    for name, *_rest in shown:
        if _rest[-1]:
            lines.append(f'<img src="{rel}/{name}.png" width="200" alt="{name}">')
    lines += ["</p>", "", "| model | what it shows | what the render shows | warnings |", "|---|---|---|---|"]
    for name, file, shows, looks, warnings, _ok in shown:
        lines.append(f"| {name} (`{file}`) | {shows} | {looks} | {warnings} |")
    tmp = page + ".part"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, page)


if __name__ == "__main__":
    sys.exit(main())
