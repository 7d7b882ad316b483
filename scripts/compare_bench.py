#!/usr/bin/env python3
"""Two builds' `photonlab bench` side by side, interleaved on this machine.

    scripts/compare_bench.py OLD_BINARY NEW_BINARY [--rounds 3] [-- bench options]

Runs the two benches in ABBA order (old, new, new, old, ...) so that a drift of the machine's
speed over the run weighs on both alike, parses every table cell that holds one number, and
prints per cell the mean of each build over its runs and the speed of the new build relative to
the old: new/old for rates, old/new for times (a row or column in seconds), so above 1 is faster.
The spread is the range of the per-round ratios. Copy the binaries out of the build folder first:
a rebuild under a running comparison would change what is measured.
"""
import argparse
import re
import statistics
import subprocess
import sys

NUMBER = re.compile(r"^\s*(-?[0-9]+(?:\.[0-9]+)?)\s*(?:x|%)?\s*$")


def parse(text):
    """{(table header, row label, column header): value} for the cells holding one number."""
    cells, header = {}, None
    for line in text.splitlines():
        if not line.startswith("|"):
            header = None
            continue
        parts = [p.strip() for p in line.strip().strip("|").split("|")]
        if header is None:
            header = parts
            continue
        if set(parts[0]) <= set("-: "):
            continue
        for column, cell in zip(header[1:], parts[1:]):
            m = NUMBER.match(cell)
            if m:
                cells[(header[0], parts[0], column)] = float(m.group(1))
    return cells


def lower_is_better(key):
    table, row, column = key
    seconds = re.compile(r"\(s\)|seconds")  # "(s)" is a time; "(M rays/s)" a rate
    return bool(seconds.search(row) or seconds.search(column)) or "bytes" in row or "MB" in column


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--rounds", type=int, default=3, help="runs of each build (default 3)")
    ap.add_argument("bench_args", nargs="*", help="after --: options for photonlab bench")
    # argparse does not take options after "--" into a positional list: split them off first.
    argv = sys.argv[1:]
    bench = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.bench_args = a.bench_args + bench
    runs = {"old": [], "new": []}
    order = []
    for r in range(a.rounds):
        order += ["old", "new"] if r % 2 == 0 else ["new", "old"]
    for which in order:
        binary = a.old if which == "old" else a.new
        out = subprocess.run([binary, "bench", *a.bench_args], capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(f"compare_bench: {binary} bench failed: {out.stderr.strip().splitlines()[-1:]}")
        runs[which].append(parse(out.stdout))
        print(f"  ran {which} ({len(runs[which])}/{a.rounds})", file=sys.stderr)
    keys = [k for k in runs["old"][0] if all(k in r for r in runs["old"] + runs["new"])]
    print(f"| table | row | column | old (mean of {a.rounds}) | new | new speed / old | range over rounds |")
    print("|---|---|---|---|---|---|---|")
    for key in keys:
        old = [r[key] for r in runs["old"]]
        new = [r[key] for r in runs["new"]]
        if lower_is_better(key):
            ratio = statistics.mean(old) / statistics.mean(new) if statistics.mean(new) else float("nan")
            rounds = [o / n for o, n in zip(old, new) if n]
        else:
            ratio = statistics.mean(new) / statistics.mean(old) if statistics.mean(old) else float("nan")
            rounds = [n / o for o, n in zip(old, new) if o]
        spread = f"{min(rounds):.3f}-{max(rounds):.3f}" if rounds else ""
        print(f"| {key[0]} | {key[1]} | {key[2]} | {statistics.mean(old):.4g} | {statistics.mean(new):.4g} | "
              f"{ratio:.3f} | {spread} |")


if __name__ == "__main__":
    main()
