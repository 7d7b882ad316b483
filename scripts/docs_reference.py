#!/usr/bin/python3
"""Writes the documentation's generated reference pages from the program that they describe:

    python3 scripts/docs_reference.py            # docs/pages/reference/{cli,integrators,experiment-keys,metadata}.md
    python3 scripts/docs_reference.py --check    # exit 1, naming the stale pages, if any differs

Each page is `photonlab reference PAGE` verbatim (the command line from CLI11's definitions, the
integrators from the registry, the experiment keys from experimentKeys(), the metadata keys from
metadataKeys()). tests/test_docs.py runs --check, so a changed flag, parameter or key fails the
tests until the pages are regenerated."""
import argparse
import os
import subprocess
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
PAGES = {"cli": "cli.md", "integrators": "integrators.md", "experiment": "experiment-keys.md", "metadata": "metadata.md"}


def generate(photonlab, name):
    r = subprocess.run([photonlab, "reference", name], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{photonlab} reference {name} failed: {r.stderr.strip()}")
    return r.stdout


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--check", action="store_true", help="compare instead of writing")
    p.add_argument("--photonlab", default=os.path.join(ROOT, "build", "photonlab"))
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "pages", "reference"))
    a = p.parse_args(argv)
    stale = []
    try:
        for name, file in PAGES.items():
            path = os.path.join(a.out, file)
            text = generate(a.photonlab, name)
            old = open(path, encoding="utf-8").read() if os.path.exists(path) else None
            if old == text:
                continue
            stale.append(path)
            if not a.check:
                with open(path + ".tmp", "w", encoding="utf-8") as f:
                    f.write(text)
                os.replace(path + ".tmp", path)
    except (RuntimeError, OSError) as e:
        print(f"docs_reference: {e}", file=sys.stderr)
        return 2
    if a.check and stale:
        print("docs_reference: stale (regenerate with python3 scripts/docs_reference.py): " + ", ".join(stale), file=sys.stderr)
        return 1
    for path in stale:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
