#!/usr/bin/env python3
"""tests/cluster/bench_cluster.py — HAProxy + umbrad numbers for "Running many" (docs/running-many.md).

    BUILD=build python3 tests/cluster/bench_cluster.py        (make bench-cluster)

1. Throughput: the same load (the 128x128 scenes of test_cluster.py, concurrency 6) through
   the balancer to 1 daemon, then to 3.
2. Cache affinity: K scenes, each with its own spot-lit caster and its own small OBJ model,
   sent round after round by 6 clients, once with X-Umbra-Affinity = the scene's name and once
   without (round robin). The daemons run with a small shadow atlas (--atlas-size 2048: four
   1024² spot maps) and a small model cache, so a daemon that sees every scene evicts, and one
   that sees a third of them keeps them. Hit rates come from the daemons' /metrics
   (umbra_shadow_cache_hits_total / _misses_total, umbra_model_cache_hits_total / _misses_total),
   counted over the load only.
Loopback only, bounded loops; numbers on a shared 2-core machine vary +-20 % run to run.
"""
import base64
import http.client
import json
import os
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "deploy"))
sys.path.insert(0, HERE)
import cluster  # noqa: E402
import test_cluster  # noqa: E402

BUILD = os.environ.get("BUILD", "build")
CONCURRENCY = 6


def run_load(port, jobs):
    """Sends jobs [(body, headers)] from CONCURRENCY threads; returns (seconds, failures)."""
    lock = threading.Lock()
    state = {"next": 0, "bad": 0}

    def worker():
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
        while True:
            with lock:
                i = state["next"]
                state["next"] += 1
            if i >= len(jobs):
                break
            body, headers = jobs[i]
            try:
                status, _, _ = test_cluster.post(conn, body, headers)
            except (OSError, http.client.HTTPException):
                status = 0
                conn.close()
                conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
            if status != 200:
                with lock:
                    state["bad"] += 1
        conn.close()

    threads = [threading.Thread(target=worker) for _ in range(CONCURRENCY)]
    t0 = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.monotonic() - t0, state["bad"]


def counters(c, names):
    out = dict.fromkeys(names, 0.0)
    for d in c.daemons:
        for n in names:
            out[n] += test_cluster.metric(d.port, n) or 0.0
    return out


def grid_obj(k, n=24):
    """A wavy n x n grid as OBJ text, different for each k (so each model is its own cache entry)."""
    lines = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = i / n - 0.5, j / n - 0.5
            lines.append("v %.5f %.5f %.5f" % (x, 0.05 * ((i * (k + 1) + j) % 5), z))
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            lines.append("f %d %d %d" % (a, a + 1, a + n + 2))
            lines.append("f %d %d %d" % (a, a + n + 2, a + n + 1))
    return "\n".join(lines) + "\n"


def affinity_scene(k):
    s = test_cluster.scene(k)
    s["objects"][1]["transform"] = {"translation": [0.15 * k - 1.0, 1, 0.1 * (k % 3)]}
    s["objects"].append({"shape": "model", "data": base64.b64encode(grid_obj(k).encode()).decode(),
                         "format": "obj", "material": "grey", "transform": {"translation": [1.5, 0.3, -1.0]}})
    s["lights"] = [{"type": "spot", "position": [-2, 5, 2], "direction": [2, -5, -2], "intensity": 80,
                    "range": 20, "outer_angle": 40, "shadow": {"resolution": 1024, "filter": "hard"}}]
    return s


def throughput(n_daemons, bodies, n):
    c = cluster.Cluster(build=BUILD, daemons=n_daemons, port=0, stats_port=0)
    try:
        c.start()
        run_load(c.port, [(bodies[i % len(bodies)], {}) for i in range(12)])  # warm
        secs, bad = run_load(c.port, [(bodies[i % len(bodies)], {}) for i in range(n)])
        return n / secs, bad
    finally:
        c.stop()
        c.cleanup()


def affinity(use_header, k_scenes, rounds, model_cache):
    names = ["umbra_shadow_cache_hits_total", "umbra_shadow_cache_misses_total",
             "umbra_model_cache_hits_total", "umbra_model_cache_misses_total"]
    c = cluster.Cluster(build=BUILD, daemons=3, port=0, stats_port=0,
                        flags=["--atlas-size", "2048", "--model-cache", str(model_cache)])
    bodies = [json.dumps(affinity_scene(k)).encode() for k in range(k_scenes)]
    jobs = []
    for _ in range(rounds):
        for k in range(k_scenes):
            jobs.append((bodies[k], {"X-Umbra-Affinity": "scene-%d" % k} if use_header else {}))
    try:
        c.start()
        before = counters(c, names)
        secs, bad = run_load(c.port, jobs)
        after = counters(c, names)
        d = {n: after[n] - before[n] for n in names}
        sh = d[names[0]] / max(1.0, d[names[0]] + d[names[1]])
        mh = d[names[2]] / max(1.0, d[names[2]] + d[names[3]])
        return sh, mh, len(jobs) / secs, bad, c.sessions()
    finally:
        c.stop()
        c.cleanup()


def main():
    bodies = [json.dumps(test_cluster.scene(k)).encode() for k in range(4)]
    n = int(os.environ.get("BENCH_RENDERS", "240"))
    for daemons in (1, 3):
        rate, bad = throughput(daemons, bodies, n)
        print("throughput: %d daemon(s) behind haproxy, %d renders 128x128, c=%d: %.1f renders/s, %d failed"
              % (daemons, n, CONCURRENCY, rate, bad), flush=True)
    # One decoded model: measure it, then allow room for four.
    probe = cluster.Cluster(build=BUILD, daemons=1, port=0, stats_port=0)
    try:
        probe.start()
        run_load(probe.port, [(json.dumps(affinity_scene(0)).encode(), {})])
        one_model = test_cluster.metric(probe.daemons[0].port, "umbra_model_cache_bytes") or 65536
    finally:
        probe.stop()
        probe.cleanup()
    model_cache = int(one_model * 4.5)
    k_scenes, rounds = 12, 6
    for use_header in (False, True):
        sh, mh, rate, bad, sess = affinity(use_header, k_scenes, rounds, model_cache)
        print("affinity %-11s %d scenes x %d rounds, c=%d: shadow-map cache hits %.0f %%, model cache hits "
              "%.0f %%, %.1f renders/s, %d failed, per daemon %s"
              % ("on:" if use_header else "off (rr):", k_scenes, rounds, CONCURRENCY, 100 * sh, 100 * mh,
                 rate, bad, sess), flush=True)
    print("(atlas 2048 = four 1024^2 spot maps per daemon; model cache %d bytes = 4.5 models)" % model_cache)
    return 0


if __name__ == "__main__":
    sys.exit(main())
