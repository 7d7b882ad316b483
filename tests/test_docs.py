"""The documentation: README short and starting with its two commands, the generated reference
pages equal to what the program prints, the site built by MkDocs in strict mode (broken links
fail), and the built site opening in a real browser with its navigation and images."""
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
PHOTONLAB = os.path.join(ROOT, "build", "photonlab")
TWO_COMMANDS = [
    "bash scripts/quickstart.sh   # install what is missing, build, run the default experiment; prints where its report is",
    "bash scripts/test.sh         # install what is missing, build, run every test (Catch2 via ctest, then pytest)",
]


def readme():
    return open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()


def test_readme_is_short_and_starts_with_exactly_the_two_commands():
    text = readme()
    assert len(text.splitlines()) <= 250
    first_block = re.search(r"```sh\n(.*?)```", text, re.S)
    assert first_block and first_block.start() < 200, "the two commands come first"
    assert first_block.group(1).strip().splitlines() == TWO_COMMANDS
    # .ci/run calls the second one.
    assert "scripts/test.sh" in open(os.path.join(ROOT, ".ci", "run"), encoding="utf-8").read()


def test_readme_and_pages_hold_no_commit_hashes_or_session_history():
    files = [os.path.join(ROOT, "README.md"), os.path.join(ROOT, "CHANGELOG.md")]
    for folder, _, names in os.walk(os.path.join(ROOT, "docs", "pages")):
        files += [os.path.join(folder, n) for n in names if n.endswith(".md")]
    for f in files:
        text = open(f, encoding="utf-8").read()
        hashes = [h for h in re.findall(r"\b[0-9a-f]{7,40}\b", text) if re.search(r"[a-f]", h) and re.search(r"\d", h)]
        assert not hashes, f"{f}: commit-like tokens {hashes[:5]}"
        # "render session" is a part of the code (render/session.h); a working session is history.
        history = re.search(r"\b(this|last|previous|next|earlier|later|first|second|third|\w+th|one|each|every) session\b|"
                            r"\bsessions?\s+(\d+|notes?|logs?|history)\b|\bdiary\b", text, re.I)
        assert not history, f"{f}: session history belongs nowhere ({history.group(0) if history else ''})"


def test_readme_links_resolve():
    for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", readme()):
        if target.startswith("http"):
            continue
        assert os.path.exists(os.path.join(ROOT, target)), f"README links to a missing {target}"


def test_every_page_in_the_navigation_is_committed():
    # A page that exists here but is ignored by git (results/ once swallowed docs/pages/results/)
    # builds locally and breaks in every fresh clone.
    nav = re.findall(r":\s*([\w/-]+\.md)\s*$", open(os.path.join(ROOT, "docs", "mkdocs.yml"), encoding="utf-8").read(), re.M)
    assert len(nav) >= 30
    r = subprocess.run(["git", "-C", ROOT, "ls-files", "docs/pages"], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip("not a git checkout")
    tracked = set(r.stdout.split())
    for page in nav:
        assert f"docs/pages/{page}" in tracked, f"docs/pages/{page} is in the navigation but not committed"


def test_generated_reference_pages_match_the_program():
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "docs_reference.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_generated_pages_hold_no_stray_html():
    # Text such as OUT.s<S>t<T>.ext must not become a tag (<s> is a strikethrough) outside code.
    for name in ["cli.md", "integrators.md", "experiment-keys.md", "metadata.md"]:
        text = open(os.path.join(ROOT, "docs", "pages", "reference", name), encoding="utf-8").read()
        text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
        assert ROOT not in text, f"{name} names this checkout's folder: the page must be the same in every clone"
        outside_code = re.sub(r"`[^`]*`", "", text)
        assert not re.search(r"<[A-Za-z/]", outside_code), f"{name}: {re.search(r'.{30}<[A-Za-z/].{30}', outside_code)}"


def test_every_flag_and_key_is_in_the_reference():
    cli = open(os.path.join(ROOT, "docs", "pages", "reference", "cli.md"), encoding="utf-8").read()
    for sub in ["render", "info", "compare", "merge", "run", "bench", "integrators", "reference"]:
        assert f"## photonlab {sub}" in cli
        help_text = subprocess.run([PHOTONLAB, sub, "--help"], capture_output=True, text=True).stdout
        for flag in set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]+)", help_text)) - {"--help"}:
            assert f"`{flag}" in cli or f",{flag}`" in cli or f"{flag}`" in cli, f"{sub} {flag} missing from cli.md"
        assert "docs/pages/" in help_text, f"photonlab {sub} --help names no documentation page"
    integrators = open(os.path.join(ROOT, "docs", "pages", "reference", "integrators.md"), encoding="utf-8").read()
    names = subprocess.run([PHOTONLAB, "integrators"], capture_output=True, text=True).stdout
    for line in names.splitlines():
        if not line.startswith(" "):
            assert f"**`{line.split(':')[0]}`**" in integrators


def mkdocs():
    exe = shutil.which("mkdocs")
    assert exe, "mkdocs is missing: scripts/setup.sh installs Debian's mkdocs and mkdocs-material"
    return exe


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("site"))
    r = subprocess.run([mkdocs(), "build", "--strict", "-q", "-f", os.path.join(ROOT, "docs", "mkdocs.yml"), "-d", out],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    return out


def test_site_builds_strictly_with_every_page(site):
    for page in ["index.html", "reference/cli.html", "reference/integrators.html", "reference/experiment-keys.html",
                 "reference/metadata.html", "how-to/extend.html", "results/smallvcm.html", "explanation/tests.html"]:
        assert os.path.isfile(os.path.join(site, page)), page


def chromium():
    exe = shutil.which("chromium")
    assert exe, "chromium is missing: scripts/setup.sh installs it"
    return [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]


def test_site_opens_in_a_browser_with_navigation_and_images(site, tmp_path):
    index = "file://" + os.path.join(site, "index.html")
    dom = subprocess.run(chromium() + ["--dump-dom", index], capture_output=True, text=True, timeout=120).stdout
    # The navigation: each section, and every page it links exists in the built site.
    for section in ["Getting started", "How-to guides", "Reference", "Explanation", "Results"]:
        assert section in dom, f"navigation lacks {section}"
    links = set(re.findall(r'href="((?:getting-started|how-to|reference|explanation|results)/[^"#]+\.html)', dom))
    assert len(links) >= 30
    for link in links:
        assert os.path.isfile(os.path.join(site, link)), f"navigation links a missing {link}"
    # The picture on the home page loads: the screenshot holds the Cornell box's red wall.
    shot = str(tmp_path / "index.png")
    subprocess.run(chromium() + [f"--screenshot={shot}", "--window-size=1280,1400", index],
                   capture_output=True, text=True, timeout=120)
    px = oiio.ImageBuf(shot).get_pixels(oiio.UINT8)[:, :, :3].astype(int)
    picture = oiio.ImageBuf(os.path.join(ROOT, "docs", "pages", "images", "cornell-spheres-path.png"))
    img = picture.get_pixels(oiio.UINT8)[:, :, :3].astype(int)
    wall = img[img.shape[0] // 2, img.shape[1] // 12]  # the left wall, halfway down
    assert wall[0] > wall[1] + 40, "expected the red wall there"
    near = np.all(np.abs(px - wall) <= 25, axis=2).mean()
    assert near > 0.002, "the home page's picture did not load"
