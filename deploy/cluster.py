#!/usr/bin/env python3
"""deploy/cluster.py — N umbrad daemons behind a real HAProxy, on this machine.

One command (also `make cluster`):
    python3 deploy/cluster.py up [--daemons 3] [--port 8080] [--stats-port 8404]
                                 [--build build] [-- UMBRAD FLAGS...]
starts the daemons on free loopback ports, writes deploy/haproxy.cfg.in with those ports into
a temporary directory, runs `haproxy -db` on 127.0.0.1:PORT (stats page and Prometheus metrics
on STATS-PORT) and stays in the foreground until Ctrl-C, which drains everything. Port 0 picks
free ports (what the tests do).

As a library (tests/cluster/, stdlib only):
    c = Cluster(build="build", daemons=3); c.start()
    c.url, c.stats_url; c.kill(i, signal.SIGKILL); c.restart(i); c.server_rows(); c.stop()
Daemon i is the HAProxy server "umbra<i+1>". Every wait is bounded (timeouts in seconds);
start() raises ClusterError with the tail of the failing log.
"""
import argparse
import csv
import http.client
import io
import os
import shutil
import signal
import socket
import string
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATE = os.path.join(HERE, "haproxy.cfg.in")
# The backends of haproxy.cfg.in over the same daemons: round robin, X-Umbra-Affinity, and the
# GET form of renders (/v1/renders, by client address).
BACKENDS = ("umbrad", "umbrad_affinity", "umbrad_renders")


class ClusterError(Exception):
    pass


def free_port():
    """A loopback port free now (the kernel's pick; another process could take it later)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http_get(port, path, timeout=5.0):
    """(status, body bytes) of GET http://127.0.0.1:PORT/PATH; (0, b"") when unreachable."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        conn.request("GET", path)
        r = conn.getresponse()
        return r.status, r.read()
    except OSError:
        return 0, b""
    finally:
        conn.close()


def log_tail(path, n=20):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-n:])
    except OSError:
        return ""


class Daemon:
    """One umbrad: its process, port (kept across restarts) and log file."""

    def __init__(self, cluster, index):
        self.cluster, self.index = cluster, index
        self.name = "umbra%d" % (index + 1)
        self.port = 0
        self.proc = None
        self.log_path = os.path.join(cluster.dir, self.name + ".log")
        self.starts = 0

    def start(self, timeout=240.0):
        """Starts it (on its old port after the first time) and waits for /readyz 200."""
        self.spawn()
        self.wait_ready(timeout)

    def spawn(self):
        c = self.cluster
        self.port_file = os.path.join(c.dir, self.name + ".port")
        if os.path.exists(self.port_file):
            os.unlink(self.port_file)
        listen = "127.0.0.1:%d" % self.port
        log = open(self.log_path, "a")
        self.proc = subprocess.Popen([c.umbrad, "--listen", listen, "--port-file", self.port_file] + c.flags,
                                     stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=c.env)
        log.close()
        self.starts += 1

    def wait_ready(self, timeout):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                raise ClusterError("%s exited %d at start:\n%s" % (self.name, self.proc.returncode,
                                                                   log_tail(self.log_path)))
            if not self.port and os.path.exists(self.port_file):
                with open(self.port_file) as f:
                    text = f.read().strip()
                self.port = int(text) if text.isdigit() else 0
            if self.port and http_get(self.port, "/readyz", 2.0)[0] == 200:
                return
            time.sleep(0.1)
        raise ClusterError("%s not ready after %.0f s:\n%s" % (self.name, timeout, log_tail(self.log_path)))

    def signal(self, sig):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(sig)

    def wait(self, timeout):
        """Exit code, or None if still running after `timeout` seconds."""
        try:
            return self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            return None


class Cluster:
    def __init__(self, build="build", daemons=3, flags=None, port=0, stats_port=0, maxconn=None,
                 deadline_ms=30000, workdir=None, haproxy="haproxy", env=None):
        self.umbrad = os.path.join(build, "umbrad")
        self.flags = list(flags or [])
        # At SIGTERM a daemon first fails /readyz while it still renders, for as long as HAProxy
        # takes to mark it DOWN (2 failed checks a second apart, haproxy.cfg.in), then drains:
        # a request the balancer sent just before it noticed is answered, not refused.
        if "--drain-grace-ms" not in self.flags:
            self.flags += ["--drain-grace-ms", "2500"]
        self.port, self.stats_port = port, stats_port
        # The balancer's timeouts follow the daemons' deadline, also when given as a flag.
        fl = self.flags
        self.deadline_ms = int(fl[fl.index("--deadline-ms") + 1]) if "--deadline-ms" in fl[:-1] else deadline_ms
        self.maxconn = maxconn
        self.haproxy = haproxy
        self.env = dict(os.environ if env is None else env)
        self.own_dir = workdir is None
        self.dir = workdir or tempfile.mkdtemp(prefix="umbra-cluster.")
        self.daemons = [Daemon(self, i) for i in range(daemons)]
        self.lb = None
        self.lb_log = os.path.join(self.dir, "haproxy.log")

    @property
    def url(self):
        return "http://127.0.0.1:%d" % self.port

    @property
    def stats_url(self):
        return "http://127.0.0.1:%d/stats" % self.stats_port

    def _write_config(self):
        servers = "".join("    server %s 127.0.0.1:%d\n" % (d.name, d.port) for d in self.daemons)
        affinity = "".join("    server %s 127.0.0.1:%d track umbrad/%s\n" % (d.name, d.port, d.name)
                           for d in self.daemons)
        # --deadline-ms 0 (none): give renders five minutes at the balancer.
        deadline_s = (self.deadline_ms + 999) // 1000 if self.deadline_ms > 0 else 300
        text = string.Template(open(TEMPLATE).read()).substitute(
            bind="127.0.0.1:%d" % self.port, stats_bind="127.0.0.1:%d" % self.stats_port,
            servers=servers.rstrip("\n"), affinity_servers=affinity.rstrip("\n"), maxconn=self.maxconn or self._workers(),
            deadline_s=deadline_s, server_timeout_s=deadline_s + 5, client_timeout_s=2 * deadline_s + 10)
        path = os.path.join(self.dir, "haproxy.cfg")
        with open(path, "w") as f:
            f.write(text)
        return path

    def _workers(self):
        """maxconn per server = the daemons' render workers (from /metrics)."""
        _, body = http_get(self.daemons[0].port, "/metrics")
        for line in body.decode(errors="replace").splitlines():
            if line.startswith("umbra_workers "):
                return max(1, int(float(line.split()[1])))
        return 2

    def start(self, timeout=240.0):
        for d in self.daemons:      # in parallel: warm-up is most of a start
            d.spawn()
        for d in self.daemons:
            d.wait_ready(timeout)
        # The balancer's ports are picked here when 0: a port taken in between makes haproxy
        # fail to bind, so try a few picks.
        want_port, want_stats = self.port, self.stats_port
        for attempt in range(5):
            self.port = want_port or free_port()
            self.stats_port = want_stats or free_port()
            cfg = self._write_config()
            check = subprocess.run([self.haproxy, "-c", "-f", cfg], capture_output=True, text=True)
            if check.returncode != 0:
                raise ClusterError("haproxy -c rejected %s:\n%s" % (cfg, check.stdout + check.stderr))
            log = open(self.lb_log, "a")
            self.lb = subprocess.Popen([self.haproxy, "-db", "-f", cfg], stdin=subprocess.DEVNULL,
                                       stdout=log, stderr=log)
            log.close()
            if self.wait_status({d.name: "UP" for d in self.daemons}, 30.0):
                return self
            self.lb.kill()
            self.lb.wait()
            if want_port and want_stats:
                break
        raise ClusterError("haproxy did not come up:\n%s" % log_tail(self.lb_log))

    def stats_rows(self):
        """Every row of the stats CSV (dicts); [] when unreachable."""
        status, body = http_get(self.stats_port, "/stats;csv")
        if status != 200:
            return []
        return list(csv.DictReader(io.StringIO(body.decode(errors="replace").lstrip("# "))))

    def server_rows(self, backend="umbrad"):
        """{server name: stats row} of a backend (umbrad holds the health checks)."""
        return {r["svname"]: r for r in self.stats_rows()
                if r.get("pxname") == backend and r.get("svname") not in ("FRONTEND", "BACKEND")}

    def sessions(self):
        """{server name: requests sent to it by any backend} (stats `stot`)."""
        out = {d.name: 0 for d in self.daemons}
        for r in self.stats_rows():
            if r.get("pxname") in BACKENDS and r.get("svname") in out:
                out[r["svname"]] += int(r.get("stot") or 0)
        return out

    def backend_total(self, field):
        """A counter (wretr, wredis, ...) summed over the backends' BACKEND rows."""
        return sum(int(r.get(field) or 0) for r in self.stats_rows()
                   if r.get("pxname") in BACKENDS and r.get("svname") == "BACKEND")

    @staticmethod
    def row_is(row, state):
        """UP = up with a passed check (not the optimistic "UP 1/2" of a new server); DOWN."""
        if state == "UP":
            return row.get("status") == "UP" and row.get("check_status", "").startswith("L7OK")
        return row.get("status", "").startswith(state)

    def wait_status(self, want, timeout):
        """Waits until every named server is in state want[name] (UP/DOWN); bool."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.lb is not None and self.lb.poll() is not None:
                return False
            rows = self.server_rows()
            if rows and all(self.row_is(rows.get(n, {}), s) for n, s in want.items()):
                return True
            time.sleep(0.05)
        return False

    def kill(self, i, sig):
        self.daemons[i].signal(sig)

    def restart(self, i, timeout=240.0):
        d = self.daemons[i]
        if d.proc and d.proc.poll() is None:
            raise ClusterError("%s is still running" % d.name)
        d.start(timeout)

    def stop(self, drain_timeout=90.0):
        """Drains the daemons (SIGTERM), then stops haproxy. Returns {name: exit code}."""
        codes = {}
        for d in self.daemons:
            d.signal(signal.SIGTERM)
        for d in self.daemons:
            if d.proc is None:
                continue
            code = d.wait(drain_timeout)
            if code is None:
                d.proc.kill()
                code = d.proc.wait()
            codes[d.name] = code
        if self.lb is not None and self.lb.poll() is None:
            self.lb.terminate()
            try:
                self.lb.wait(10)
            except subprocess.TimeoutExpired:
                self.lb.kill()
                self.lb.wait()
        return codes

    def cleanup(self):
        if self.own_dir:
            shutil.rmtree(self.dir, ignore_errors=True)


def main(argv):
    ap = argparse.ArgumentParser(description="N umbrad behind HAProxy on loopback (Ctrl-C stops).")
    ap.add_argument("command", choices=["up"])
    ap.add_argument("--daemons", type=int, default=3)
    ap.add_argument("--port", type=int, default=8080, help="balancer port (0 = any free)")
    ap.add_argument("--stats-port", type=int, default=8404, help="stats + /metrics port (0 = any free)")
    ap.add_argument("--build", default=os.environ.get("BUILD", "build"))
    ap.add_argument("flags", nargs="*", help="umbrad flags (after --)")
    a = ap.parse_args(argv)
    if not shutil.which("haproxy"):
        print("cluster: haproxy is not installed (sh deploy/install-deps.sh)", file=sys.stderr)
        return 1
    c = Cluster(build=a.build, daemons=a.daemons, flags=a.flags, port=a.port, stats_port=a.stats_port)
    stop = []
    # Ctrl-C in a terminal also reaches the daemons (same process group): they drain by
    # themselves; stop() then collects them. Both signals end the wait loop.
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.append(1))
    try:
        c.start()
        print("umbra: %d daemons behind %s  (POST /v1/render; optional header X-Umbra-Affinity)" %
              (len(c.daemons), c.url))
        print("  stats %s   Prometheus http://127.0.0.1:%d/metrics   logs %s" % (c.stats_url, c.stats_port, c.dir))
        for d in c.daemons:
            print("  %s 127.0.0.1:%d pid %d" % (d.name, d.port, d.proc.pid))
        print("Ctrl-C drains and stops.", flush=True)
        while not stop:
            time.sleep(0.5)
    except KeyboardInterrupt:
        pass
    except ClusterError as e:
        print("cluster: %s" % e, file=sys.stderr)
        c.stop()
        return 1
    codes = c.stop()
    print("stopped: %s" % ", ".join("%s exit %d" % kv for kv in codes.items()))
    return 0 if all(v == 0 for v in codes.values()) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
