#!/usr/bin/python3
"""Seed corpora for the fuzz targets (scripts/fuzz.sh): the shipped scenes as they are (JSON with
a data-URI buffer), the same scenes as GLB (JSON chunk + BIN chunk), one with a small embedded PNG
texture, and the shipped experiment configs.

    scripts/make_fuzz_corpus.py OUT_DIR      # writes OUT_DIR/gltf/ and OUT_DIR/experiment/"""
import base64
import glob
import json
import os
import shutil
import struct
import sys
import zlib

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def to_glb(doc):
    """The glTF document with its single data-URI buffer moved into a GLB BIN chunk."""
    doc = json.loads(json.dumps(doc))
    (buffer,) = doc["buffers"]
    data = base64.b64decode(buffer.pop("uri").split(",", 1)[1])
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks


def tiny_png(w=2, h=2):
    raw = b"".join(b"\0" + bytes([255, 0, 0] * w) for _ in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main(out):
    gltf_dir, exp_dir = os.path.join(out, "gltf"), os.path.join(out, "experiment")
    os.makedirs(gltf_dir, exist_ok=True)
    os.makedirs(exp_dir, exist_ok=True)
    for path in sorted(glob.glob(os.path.join(ROOT, "scenes", "*.gltf"))):
        name = os.path.splitext(os.path.basename(path))[0]
        shutil.copy(path, os.path.join(gltf_dir, name + ".gltf"))
        with open(path) as f:
            doc = json.load(f)
        with open(os.path.join(gltf_dir, name + ".glb"), "wb") as f:
            f.write(to_glb(doc))
    # The furnace with a PNG base-colour texture (embedded as a data URI).
    with open(os.path.join(ROOT, "scenes", "furnace.gltf")) as f:
        doc = json.load(f)
    doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(tiny_png()).decode()}]
    doc["textures"] = [{"source": 0}]
    doc["materials"][0].setdefault("pbrMetallicRoughness", {})["baseColorTexture"] = {"index": 0}
    with open(os.path.join(gltf_dir, "textured.gltf"), "w") as f:
        json.dump(doc, f)
    for path in sorted(glob.glob(os.path.join(ROOT, "experiments", "*.toml"))):
        shutil.copy(path, exp_dir)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
