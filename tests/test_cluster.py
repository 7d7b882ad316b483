"""scripts/cluster.py against a real Dask cluster on localhost: a `dask scheduler` and two
`dask worker` processes, each worker in its own process group so that killing it takes its
photonlab child with it, as a lost machine would."""
import os
import signal
import socket
import subprocess
import sys
import time

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
CLUSTER = os.path.join(ROOT, "scripts", "cluster.py")
PHOTONLAB = os.path.join(ROOT, "build", "photonlab")
SCENE = os.path.join(ROOT, "scenes", "cornell-box.gltf")
PYTHON = "/usr/bin/python3"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_worker(address, name):
    return subprocess.Popen([PYTHON, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1", "--nworkers", "1",
                             "--no-dashboard", "--name", name], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


@pytest.fixture(scope="module")
def cluster():
    assert os.access(PHOTONLAB, os.X_OK), "build/photonlab is missing: run scripts/setup.sh"
    port = free_port()
    address = "tcp://127.0.0.1:%d" % port
    scheduler = subprocess.Popen([PYTHON, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                                  "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 start_new_session=True)
    workers = [start_worker(address, "w%d" % i) for i in range(2)]
    from distributed import Client
    with Client(address, timeout="30s") as client:
        client.wait_for_workers(2, timeout=60)
    yield {"address": address, "workers": workers}
    for p in workers + [scheduler]:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        p.wait()


def identical(a, b):
    r = subprocess.run([PHOTONLAB, "compare", a, b], capture_output=True, text=True)
    return r.returncode == 0 and '"rmse": 0,' in r.stdout


PPPM = ["--integrator", "pppm", "--passes", "8", "--photons-per-pass", "100000", "--width", "48"]


def test_a_pppm_render_in_four_slices_is_the_one_process_render_even_when_a_worker_dies(cluster, tmp_path):
    whole = str(tmp_path / "whole.exr")
    subprocess.run([PHOTONLAB, "render", SCENE, "-o", whole, "-q"] + PPPM, check=True)
    out = str(tmp_path / "sliced.exr")
    r = subprocess.run([PYTHON, CLUSTER, "render", SCENE, "-o", out, "--chunks", "4", "--scheduler", cluster["address"], "--"]
                       + PPPM, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert identical(out, whole)
    assert "4 slices of 8 passes" in r.stderr

    # Again, and kill a worker (its process group: nanny, worker and the photonlab it runs) as
    # soon as it is rendering a slice. Dask runs that slice again on the other worker.
    out2 = str(tmp_path / "sliced-after-a-loss.exr")
    job = subprocess.Popen([PYTHON, CLUSTER, "render", SCENE, "-o", out2, "--chunks", "4", "--scheduler", cluster["address"],
                            "--"] + PPPM, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    victim = cluster["workers"][0]
    killed = False
    deadline = time.time() + 60
    while time.time() < deadline and not killed:
        for pid in os.listdir("/proc"):
            if not pid.isdigit():
                continue
            try:
                with open("/proc/%s/comm" % pid) as f:
                    comm = f.read().strip()
                if comm == "photonlab" and os.getpgid(int(pid)) == victim.pid:
                    os.killpg(victim.pid, signal.SIGKILL)
                    killed = True
                    break
            except (OSError, ProcessLookupError):
                continue
        time.sleep(0.02)
    assert killed, "the worker never ran a slice"
    stdout, stderr = job.communicate(timeout=300)
    assert job.returncode == 0, stderr
    assert identical(out2, whole)
    cluster["workers"][0] = start_worker(cluster["address"], "w0-again")


def test_an_experiment_through_the_cluster_has_photonlab_runs_metrics(cluster, tmp_path):
    # A small experiment with sample and pass budgets (deterministic): every error column of
    # metrics.csv equals `photonlab run`'s; only the seconds differ.
    config = tmp_path / "small.toml"
    config.write_text('name = "small"\nscene = "%s"\nwidth = 24\nseeds = [1, 2]\n[reference]\nintegrator = "path"\nspp = 32\n'
                      '[[run]]\nlabel = "Path"\nintegrator = "path"\nspp = 4\n[[run]]\nlabel = "PPPM"\nintegrator = "pppm"\n'
                      'passes = 3\nphotons_per_pass = 3000\n' % SCENE)
    subprocess.run([PHOTONLAB, "run", str(config), "--out", str(tmp_path / "local"), "-q"], check=True, capture_output=True)
    r = subprocess.run([PYTHON, CLUSTER, "run", str(config), "--out", str(tmp_path / "cluster"), "--scheduler",
                        cluster["address"]], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr

    def rows(folder):
        lines = (tmp_path / folder / "metrics.csv").read_text().splitlines()
        header = lines[0].split(",")
        keep = [i for i, h in enumerate(header) if h != "seconds"]
        return [[line.split(",")[i] for i in keep] for line in lines]

    # The header; per seed, checkpoints after 1, 2 and 4 samples, and after passes 1, 2 and 3.
    assert len(rows("local")) == 1 + 2 * (3 + 3)
    assert rows("cluster") == rows("local")
    assert (tmp_path / "cluster" / "reference.exr").exists()


def test_a_worker_without_the_binary_is_one_line_naming_it(cluster, tmp_path):
    r = subprocess.run([PYTHON, CLUSTER, "render", SCENE, "-o", str(tmp_path / "x.exr"), "--chunks", "2", "--scheduler",
                        cluster["address"], "--binary", str(tmp_path / "nowhere" / "photonlab"), "--", "--spp", "2"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode != 0
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "nowhere/photonlab does not exist there" in lines[0] and "shared filesystem" in lines[0]
    assert not (tmp_path / "x.exr").exists()
