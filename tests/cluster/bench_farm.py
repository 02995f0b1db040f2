#!/usr/bin/env python3
"""tests/cluster/bench_farm.py [N] [SIZE] — the local farm against the remote farm, same run.

    BUILD=build python3 tests/cluster/bench_farm.py 300 256      (make bench-farm-remote)

Writes N models (tests/cli/gen_models.py), renders them with `umbra-render thumb` here (-j 2),
then with `--server` on three umbrad behind HAProxy (deploy/cluster.py, -j 6 and -j 12), and
prints each run's images/s (the farm's own summary line) and whether every PNG is the same
bytes as the local farm's. Figures in docs/performance.md ("The farm on a cluster").
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "deploy"))
import cluster  # noqa: E402

BUILD = os.environ.get("BUILD", "build")


def run(inputs, out, size, extra):
    p = subprocess.run([os.path.join(BUILD, "umbra-render"), "thumb"] + inputs +
                       ["-o", out, "--size", size, "--no-progress"] + extra, capture_output=True, text=True)
    last = [l for l in p.stderr.splitlines() if " ok" in l and "images/s" in l]
    return p.returncode, last[-1] if last else p.stderr[-300:]


def same(a, b):
    names = [f for f in os.listdir(a) if f.endswith(".png")]
    return sum(open(os.path.join(a, f), "rb").read() == open(os.path.join(b, f), "rb").read() for f in names), len(names)


def main():
    n = sys.argv[1] if len(sys.argv) > 1 else "300"
    size = sys.argv[2] if len(sys.argv) > 2 else "256"
    tmp = tempfile.mkdtemp(prefix="umbra-bench-farm.")
    d = os.path.join(tmp, "models")
    subprocess.run([sys.executable, os.path.join(ROOT, "tests/cli/gen_models.py"), d, n], check=True)
    inputs = sorted(os.path.join(d, f) for f in os.listdir(d))
    print("%s models at %s², nproc %d" % (n, size, os.cpu_count()))
    code, line = run(inputs, os.path.join(tmp, "local"), size, ["-j", "2"])
    print("local  -j 2  : exit %d  %s" % (code, line))
    os.makedirs(os.path.join(tmp, "cluster"))
    c = cluster.Cluster(build=BUILD, daemons=3, port=0, stats_port=0, workdir=os.path.join(tmp, "cluster"))
    try:
        c.start()
        for j in ("6", "12"):
            out = os.path.join(tmp, "remote" + j)
            code, line = run(inputs, out, size, ["--server", c.url, "-j", j])
            print("remote -j %-3s: exit %d  %s  (same bytes: %d of %d)" %
                  ((j, code, line) + same(os.path.join(tmp, "local"), out)))
    finally:
        c.stop()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
