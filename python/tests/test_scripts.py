"""The example (examples/plot_channel.py) and the dataset benchmark (bench/bench_dataset.py)
run as a user runs them, with this interpreter and the built module."""

import json
import os
import subprocess
import sys

from conftest import HOP, REPO


def run(*args, cwd=None):
    path = os.pathsep.join(os.path.abspath(p) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=path)
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, cwd=cwd, env=env)


def test_example_plots_and_reports(tmp_path):
    r = run(REPO / "examples" / "plot_channel.py", "-o", tmp_path / "walk.png", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "walk.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = json.loads(r.stdout)
    assert report["frames"] == 344 and report["error"]["max"] <= report["tolerance"]
    r = run(REPO / "examples" / "plot_channel.py", HOP, "--channel", "Hips:Xposition", "--error", "0.5",
            "-o", tmp_path / "hop.png")
    assert r.returncode == 0 and json.loads(r.stdout)["tolerance"] == 0.5
    r = run(REPO / "examples" / "plot_channel.py", "--channel", "Nose:Wiggle", "-o", tmp_path / "x.png")
    assert r.returncode == 2 and "has no channel Nose:Wiggle" in r.stderr


def test_dataset_bench_runs(tmp_path):
    r = run(REPO / "bench" / "bench_dataset.py", REPO / "data", "--windows", "20", "--reread", "3",
            "--fps", "30", "--window", "16", "--output", "world_positions")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["files"] == 2 and out["windows_in_dataset"] > 0
    for way in ("kanim", "bvh_in_memory", "bvh_reread"):
        assert out[way]["windows"] > 0 and "windows_per_second" in out[way]
