#!/usr/bin/python3
"""Long renders and experiment sweeps on a Dask cluster (docs: how-to/cluster.md).

    scripts/cluster.py render SCENE -o OUT.exr --chunks N [cluster options] -- [photonlab render options]
    scripts/cluster.py run EXPERIMENT.toml [--out DIR] [cluster options]

`render` splits one render into N slices (`photonlab render --sample-range` for per-sample
integrators, `--pass-range` for pppm; the total comes from the options' --spp or --passes), runs
each as a Dask task (a photonlab process on a worker), and merges them (`photonlab merge`): the
image is bit for bit the one-process render. `run` renders an experiment's reference, then
every (run, seed) as a task (`photonlab run --reference-only`, `--only RUN:SEED`), then collects
metrics.csv with a plain `photonlab run`: the same results folder `photonlab run` writes.

Cluster options: --scheduler tcp://HOST:8786 uses a running cluster (`dask scheduler`,
`dask worker`); --slurm submits workers as Slurm jobs (dask-jobqueue); neither starts a
LocalCluster of --workers single-threaded workers on this machine. Workers run the same
photonlab binary on the same scene and output paths: a shared filesystem is assumed, and a
worker missing a path fails its task with a line naming it. A worker lost mid-task costs only
that task: Dask runs it again elsewhere, and as every slice is deterministic the result is the
same.
"""
import argparse
import os
import socket
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class ClusterError(Exception):
    pass


# ---- what runs on the workers --------------------------------------------------------------

def run_photonlab(args, needed, _after=None):
    """Runs `photonlab ARGS` on a worker; `needed` are the paths it must see (shared filesystem).
    Returns the wall time and the worker's host name. `_after` only orders tasks."""
    host = socket.gethostname()
    for path in needed:
        if not os.path.exists(path):
            raise ClusterError("worker on %s: %s does not exist there (workers need the photonlab binary, the scene "
                               "and the output folder at the same paths: a shared filesystem)" % (host, path))
    start = time.time()
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["exit status %d" % r.returncode])[-1]
        raise ClusterError("worker on %s: %s" % (host, last))
    return {"seconds": time.time() - start, "host": host}


# ---- the client ----------------------------------------------------------------------------

def connect(a):
    """A Dask client: the given scheduler, Slurm jobs, or a LocalCluster here."""
    from distributed import Client, LocalCluster
    if a.scheduler:
        return Client(a.scheduler, timeout="20s"), None
    if a.slurm:
        try:
            from dask_jobqueue import SLURMCluster
        except ImportError:
            raise ClusterError("--slurm needs dask-jobqueue (pip install dask-jobqueue)")
        cluster = SLURMCluster(cores=max(1, a.threads), processes=1, memory=a.slurm_memory, walltime=a.slurm_walltime,
                               queue=a.slurm_queue, account=a.slurm_account)
        cluster.scale(jobs=a.workers)
        return Client(cluster), cluster
    cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, dashboard_address=None, processes=True)
    return Client(cluster), cluster


def split(total, chunks):
    """Interleaved slices "k:total:chunks": slice k takes samples (passes) k, k + chunks, ...
    Contiguous ranges would give PPPM's first slice the early passes, whose larger radii make
    the gathers slower (the first half of 64 passes took 18% longer than the second): the
    slowest slice sets the wall time. Interleaved, every slice walks the whole schedule."""
    chunks = max(1, min(chunks, total))
    return ["%d:%d:%d" % (k, total, chunks) for k in range(chunks)]


def option_value(options, flag):
    for i, o in enumerate(options):
        if o == flag and i + 1 < len(options):
            return options[i + 1]
        if o.startswith(flag + "="):
            return o.split("=", 1)[1]
    return None


def wait_all(client, futures, describe):
    """Results in completion order, a progress line each; the first failure ends it."""
    from distributed import as_completed
    results = {}
    done = 0
    for future in as_completed(futures):
        try:
            result = future.result()
        except ClusterError:
            raise
        except Exception as e:  # noqa: BLE001 - a task's exception, shown in one line
            raise ClusterError("%s: %s" % (describe[future.key], e))
        done += 1
        results[future.key] = result
        print("  %d/%d %s on %s, %.2f s" % (done, len(futures), describe[future.key], result["host"], result["seconds"]),
              file=sys.stderr, flush=True)
    return results


def cmd_render(a):
    options = a.options
    binary, scene, out = os.path.abspath(a.binary), os.path.abspath(a.scene), os.path.abspath(a.output)
    if not out.endswith(".exr"):
        raise ClusterError("-o: the merged image is written as .exr")
    spp, passes = option_value(options, "--spp"), option_value(options, "--passes")
    if (spp is None) == (passes is None):
        raise ClusterError("give the total to split as --spp N (per-sample integrators) or --passes N (pppm) after --")
    total, flag = (int(spp), "--sample-range") if spp is not None else (int(passes), "--pass-range")
    workdir = os.path.abspath(a.workdir or os.path.join(os.path.dirname(out), "." + os.path.basename(out) + ".slices"))
    os.makedirs(workdir, exist_ok=True)
    client, cluster = connect(a)
    try:
        start = time.time()
        futures, describe, parts = [], {}, []
        for k, span in enumerate(split(total, a.chunks)):
            part = os.path.join(workdir, "slice-%d.exr" % k)
            args = [binary, "render", scene, "-o", part, "-q", "--threads", str(a.threads), flag, span] + options
            # pure=False: a task is a process with a file as its effect; retries: a failed attempt.
            f = client.submit(run_photonlab, args, [binary, scene, workdir], key="slice-%d-%s" % (k, os.urandom(4).hex()),
                              pure=False, retries=a.retries)
            futures.append(f)
            describe[f.key] = "slice %s" % span
            parts.append(part)
        results = wait_all(client, futures, describe)
        wall = time.time() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    r = subprocess.run([binary, "merge"] + parts + ["-o", out], capture_output=True, text=True)
    if r.returncode != 0:
        raise ClusterError((r.stderr.strip().splitlines() or ["merge failed"])[-1])
    task = sum(v["seconds"] for v in results.values()) / len(results)
    overhead = task - sum(slice_seconds(binary, p) for p in parts) / len(parts)
    print("cluster: %d slices of %d %s in %.2f s; a task took %.2f s on average, %.2f s of it outside the render loop "
          "(process start, scene load, EXR write) -> %s"
          % (len(parts), total, "passes" if flag == "--pass-range" else "samples", wall, task, overhead, out), file=sys.stderr)
    if not a.keep_slices:
        for p in parts:
            os.remove(p)
        try:
            os.rmdir(workdir)
        except OSError:
            pass
    print(out)


def cmd_run(a):
    import tomllib
    binary, config = os.path.abspath(a.binary), os.path.abspath(a.experiment)
    try:
        with open(config, "rb") as f:
            name = tomllib.load(f).get("name", os.path.splitext(os.path.basename(config))[0])
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise ClusterError("%s: %s" % (a.experiment, e))
    out = os.path.abspath(a.out or os.path.join("results", name))
    listed = subprocess.run([binary, "run", config, "--list-runs"], capture_output=True, text=True)
    if listed.returncode != 0:
        raise ClusterError((listed.stderr.strip().splitlines() or ["photonlab run --list-runs failed"])[-1])
    pairs = [line.split() for line in listed.stdout.split("\n") if line.strip()]
    base = [binary, "run", config, "--out", out, "-q", "--threads", str(a.threads)]
    client, cluster = connect(a)
    try:
        start = time.time()
        reference = client.submit(run_photonlab, base + ["--reference-only"], [binary, config], key="reference-" + os.urandom(4).hex(),
                                  pure=False, retries=a.retries)
        describe = {reference.key: "reference"}
        futures = [reference]
        for run, seed in pairs:
            f = client.submit(run_photonlab, base + ["--only", "%s:%s" % (run, seed)], [binary, config], reference,
                              key="run-%s-%s-%s" % (run, seed, os.urandom(4).hex()), pure=False, retries=a.retries)
            futures.append(f)
            describe[f.key] = "run %s, seed %s" % (run, seed)
        wait_all(client, futures, describe)
        wall = time.time() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    # Every pair is finished: a plain run collects their rows into metrics.csv.
    r = subprocess.run([binary, "run", config, "--out", out], capture_output=True, text=True)
    sys.stderr.write(r.stderr)
    if r.returncode != 0:
        raise ClusterError((r.stderr.strip().splitlines() or ["photonlab run failed"])[-1])
    print("cluster: the reference and %d runs in %.2f s -> %s" % (len(pairs), wall, out), file=sys.stderr)
    print(out)


def slice_seconds(binary, part):
    """The render time photonlab recorded in a slice (its loop, without process start and I/O)."""
    import json
    r = subprocess.run([binary, "info", part], capture_output=True, text=True)
    return float(json.loads(r.stdout)["seconds"]) if r.returncode == 0 else float("nan")


def cmd_bench(a):
    """1 and 2 single-threaded local workers on one PPPM render; the per-task overhead on every
    shipped scene; the speed-up that overhead allows on 16 and 64 workers (a model, stated)."""
    from distributed import Client, LocalCluster
    binary = os.path.abspath(a.binary)
    scene = os.path.abspath(a.scene)
    workdir = os.path.abspath(a.workdir)
    os.makedirs(workdir, exist_ok=True)
    options = ["--integrator", "pppm", "--passes", str(a.passes), "--photons-per-pass", str(a.photons_per_pass),
               "--width", str(a.width)]
    times = {}
    for workers in (1, 2, 1, 2):  # interleaved, best of two each
        with LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster) as client:
            start = time.time()
            futures, parts = [], []
            for k, span in enumerate(split(a.passes, workers)):
                part = os.path.join(workdir, "bench-%d-%d.exr" % (workers, k))
                args = [binary, "render", scene, "-o", part, "-q", "--threads", "1", "--pass-range", span] + options
                futures.append(client.submit(run_photonlab, args, [binary, scene], pure=False))
                parts.append(part)
            client.gather(futures)
            merge = time.time()
            subprocess.run([binary, "merge"] + parts + ["-o", os.path.join(workdir, "bench-%d.exr" % workers)], check=True,
                           capture_output=True)
            end = time.time()
            t = end - start
            if workers not in times or t < times[workers]["wall"]:
                times[workers] = {"wall": t, "merge": end - merge,
                                  "render": sum(slice_seconds(binary, p) for p in parts)}
    # Overhead per task on each shipped scene: a one-pass slice with few photons, wall time on
    # the worker minus the render loop's own seconds (process start, scene load, EXR write), and
    # the client's round trip minus the worker's wall time (scheduling, transfer).
    overheads = []
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster) as client:
        for path in sorted(os.listdir(os.path.join(ROOT, "scenes"))):
            if not path.endswith(".gltf"):
                continue
            s = os.path.join(ROOT, "scenes", path)
            part = os.path.join(workdir, "overhead.exr")
            args = [binary, "render", s, "-o", part, "-q", "--threads", "1", "--integrator", "pppm", "--photons-per-pass",
                    "1000", "--width", "64", "--pass-range", "0:1"]
            best = None
            for _ in range(3):
                t0 = time.time()
                r = client.submit(run_photonlab, args, [binary, s], pure=False).result()
                roundtrip = time.time() - t0
                process = r["seconds"] - slice_seconds(binary, part)
                scheduling = roundtrip - r["seconds"]
                if best is None or process + scheduling < best[0] + best[1]:
                    best = (process, scheduling)
            overheads.append((path, best[0], best[1]))
    # What one more slice costs the merge: 16 slices of one path-traced sample each at the same
    # size, merged, against 2 of them (a difference of 1 vs 2 is lost in the noise).
    merge_times = {}
    for n in (2, 16):
        parts = []
        for k in range(n):
            part = os.path.join(workdir, "merge-%d-%d.exr" % (n, k))
            subprocess.run([binary, "render", scene, "-o", part, "-q", "--spp", str(n), "--width", str(a.width),
                            "--sample-range", "%d:%d:%d" % (k, n, n)], check=True, capture_output=True)
            parts.append(part)
        t0 = time.time()
        subprocess.run([binary, "merge"] + parts + ["-o", os.path.join(workdir, "merged.exr")], check=True, capture_output=True)
        merge_times[n] = time.time() - t0
    dm = max(0.0, (merge_times[16] - merge_times[2]) / 14)
    t1, t2 = times[1], times[2]
    print("| measure | 1 worker | 2 workers |\n|---|---|---|")
    print("| wall time, %d-pass PPPM (s) | %.2f | %.2f |" % (a.passes, t1["wall"], t2["wall"]))
    print("| speed-up | 1 | %.2f× |" % (t1["wall"] / t2["wall"]))
    print("| merge (s) | %.3f | %.3f |" % (t1["merge"], t2["merge"]))
    print()
    print("| scene | process start, scene load, EXR write (s) | scheduling and transfer (s) | per task (s) |\n|---|---|---|---|")
    for path, process, scheduling in overheads:
        print("| %s | %.3f | %.3f | %.3f |" % (path, process, scheduling, process + scheduling))
    # The model: one slice per worker; a task costs its overhead o plus its passes' render time;
    # the client then merges W slices, m(W) = m1 + (W - 1)·dm (each slice read once).
    # T(W) = o + R/W + m(W), R the whole render loop's time.
    o = max(process + scheduling for name, process, scheduling in overheads if name == os.path.basename(scene))
    R, m1 = t1["render"], t1["merge"]

    def T(w):
        return o + R / w + m1 + (w - 1) * dm

    print()
    print("| workers | modelled wall time (s) | modelled speed-up |\n|---|---|---|")
    for w in (1, 2, 16, 64):
        print("| %d | %.2f | %.1f× |" % (w, T(w), T(1) / T(w)))
    print("\n(model: T(W) = o + R/W + m1 + (W - 1)·dm with o = %.3f s per task, R = %.2f s of rendering, m1 = %.3f s to "
          "merge one slice and dm = %.3f s per further slice (merging 16 slices took %.2f s, 2 took %.2f s); %s)"
          % (o, R, m1, dm, merge_times[16], merge_times[2], os.path.basename(scene)))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n", 2)[2])
    sub = ap.add_subparsers(dest="command", required=True)

    def cluster_options(p):
        p.add_argument("--scheduler", help="a running scheduler, tcp://HOST:8786")
        p.add_argument("--slurm", action="store_true", help="workers as Slurm jobs (dask-jobqueue)")
        p.add_argument("--workers", type=int, default=os.cpu_count(), help="LocalCluster workers, or Slurm jobs")
        p.add_argument("--threads", type=int, default=1, help="photonlab --threads per task (0: all the worker's cores)")
        p.add_argument("--binary", default=os.path.join(ROOT, "build", "photonlab"))
        p.add_argument("--retries", type=int, default=1, help="attempts again after a task fails (lost workers: always)")
        p.add_argument("--slurm-queue")
        p.add_argument("--slurm-account")
        p.add_argument("--slurm-memory", default="4GB")
        p.add_argument("--slurm-walltime", default="01:00:00")

    r = sub.add_parser("render", help="one render in slices")
    r.add_argument("scene")
    r.add_argument("-o", "--output", required=True)
    r.add_argument("--chunks", type=int, required=True)
    r.add_argument("--workdir", help="where slices go (shared; default: beside the output)")
    r.add_argument("--keep-slices", action="store_true")
    cluster_options(r)
    b = sub.add_parser("bench", help="1 vs 2 local workers, per-task overhead, modelled speed-up (docs: how-to/cluster.md)")
    b.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell-box.gltf"))
    b.add_argument("--passes", type=int, default=64)
    b.add_argument("--photons-per-pass", type=int, default=200000)
    b.add_argument("--width", type=int, default=256)
    b.add_argument("--workdir", default="/tmp/photonlab-cluster-bench")
    b.add_argument("--binary", default=os.path.join(ROOT, "build", "photonlab"))
    e = sub.add_parser("run", help="an experiment's reference and runs as tasks")
    e.add_argument("experiment")
    e.add_argument("--out")
    cluster_options(e)
    argv = list(sys.argv[1:] if argv is None else argv)
    # Everything after "--" is photonlab render's own options.
    passthrough = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.options = passthrough
    if a.command == "render" and a.chunks < 1:
        ap.error("--chunks: at least 1")
    try:
        {"render": cmd_render, "run": cmd_run, "bench": cmd_bench}[a.command](a)
    except ClusterError as e:
        print("cluster: %s" % e, file=sys.stderr)
        return 1
    except OSError as e:  # a scheduler that does not answer, a folder that cannot be made
        print("cluster: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
