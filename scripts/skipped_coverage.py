#!/usr/bin/env python3
"""Which lines of src/ only the tests the sanitized run skips execute.

The sanitized pass of .ci/run leaves out the ctest labels "long", "heavy" and "latency"
(scripts/test.sh). That is safe only while every line of src/ those tests execute is executed by
a test the sanitizers do run. This script builds the tests with gcov instrumentation (-O1, no
LTO) into BUILD_DIR, runs the sanitized set, records the lines of src/ it executed, runs the
skipped set, and prints every line of src/ that only the skipped set reached. Exit 0 when there
is none, 1 otherwise (a new heavy test then needs a short test of that code, or no [heavy]).

    scripts/skipped_coverage.py [--build BUILD_DIR] [--skipped LABEL_REGEX]

About ten minutes on 2 cores (the build, then every non-long test twice-ish).
"""
import argparse
import collections
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def executed_lines(build):
    """(file under src/, line) pairs with a non-zero count in the .gcda files under `build`."""
    lines = set()
    for folder, _, files in os.walk(build):
        for name in files:
            if not name.endswith(".gcda"):
                continue
            r = subprocess.run(["gcov", "--json-format", "--stdout", "--object-directory", folder, name],
                               capture_output=True, text=True, cwd=folder)
            for chunk in r.stdout.splitlines():
                if not chunk.startswith("{"):
                    continue
                for f in json.loads(chunk)["files"]:
                    path = os.path.normpath(os.path.join(folder, f["file"]))
                    source = os.path.relpath(path, ROOT)
                    if source.startswith("src" + os.sep):
                        lines.update((source, l["line_number"]) for l in f["lines"] if l["count"] > 0)
    return lines


def clear_counters(build):
    for folder, _, files in os.walk(build):
        for name in files:
            if name.endswith(".gcda"):
                os.remove(os.path.join(folder, name))


def ctest(build, *label_args):
    r = subprocess.run(["ctest", "--test-dir", build, "-j", str(os.cpu_count() or 2), "--timeout", "1800", *label_args],
                       capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"skipped_coverage: ctest {' '.join(label_args)} failed:\n{r.stdout[-3000:]}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build-coverage"))
    parser.add_argument("--skipped", default="long|heavy", help="labels the sanitized run skips (besides latency)")
    args = parser.parse_args(argv)
    build = os.path.abspath(args.build)
    subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Coverage",
                    "-DCMAKE_CXX_FLAGS=-O1 -g0 --coverage -fprofile-update=atomic", "-DCMAKE_EXE_LINKER_FLAGS=--coverage"],
                   check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", build, "-j", str(os.cpu_count() or 2)], check=True, stdout=subprocess.DEVNULL)
    clear_counters(build)
    ctest(build, "-LE", f"{args.skipped}|latency")
    kept = executed_lines(build)
    clear_counters(build)
    ctest(build, "-L", args.skipped)
    only = sorted(executed_lines(build) - kept)
    by_file = collections.defaultdict(list)
    for source, line in only:
        by_file[source].append(line)
    print(f"{len(kept)} lines of src/ executed by the sanitized set; {len(only)} only by the tests labelled {args.skipped}")
    for source, lines in sorted(by_file.items()):
        print(f"  {source}: {', '.join(map(str, lines))}")
    return 1 if only else 0


if __name__ == "__main__":
    sys.exit(main())
