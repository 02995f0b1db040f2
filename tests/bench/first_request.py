#!/usr/bin/env python3
"""tests/bench/first_request.py BUILD MODEL... — what a new model costs one request at a time (issue
28's first targets): a fresh BUILD/umbrad on a free loopback port, then per model and per round
the file POSTed with bytes it has not seen (a first import: a binary STL's header, an OBJ's or
PLY's comment, a glb's JSON padding changed, the model itself the same) and the model turned by a
different hundredth of a degree (so its shadow maps are new too: their keys hash the geometry
and its transform, and an earlier round's would be found), then the same request once more
(its warm render: model and shadow maps cached). Prints, per model, the medians over the
rounds of the first request's wall time and its Server-Timing stages, the warm request's, and
their ratio, and the warm request's stages. One client, nothing else running in the daemon; numbers only, nothing asserted.
Env: FIRST_ROUNDS (5), FIRST_SIZE (256), FIRST_UMBRAD_ARGS (extra umbrad flags)."""
import http.client, json, math, os, signal, statistics, struct, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import farm_bench  # noqa: E402  (its multipart, Server-Timing parser and table)

ROUNDS = int(os.environ.get("FIRST_ROUNDS", "5"))
farm_bench.SIZE = int(os.environ.get("FIRST_SIZE", "256"))
FORMATS = {".stl": "stl", ".obj": "obj", ".ply": "ply", ".glb": "glb"}


def fresh(data, fmt, n):
    """The model's bytes made new (round n) without changing the model."""
    tag = b"umbra first request %d" % n
    if fmt == "stl" and len(data) >= 84 and not data[:5].lower() == b"solid":
        return tag.ljust(80, b" ") + data[80:]
    if fmt == "obj":
        return data + b"\n# " + tag + b"\n"
    if fmt == "ply":
        nl = data.index(b"\n", data.index(b"\n") + 1) + 1   # after "ply" and "format ..."
        return data[:nl] + b"comment " + tag + b"\n" + data[nl:]
    if fmt == "glb":
        total, jlen = struct.unpack_from("<I", data, 8)[0], struct.unpack_from("<I", data, 12)[0]
        pad = b" " * (4 * (n + 1))   # JSON chunks are padded with spaces
        out = data[:8] + struct.pack("<II", total + len(pad), jlen + len(pad)) + data[16:20 + jlen] + pad + data[20 + jlen:]
        return out
    raise ValueError("cannot make new bytes of a %s" % fmt)


def start(build, tmp):
    port_file = os.path.join(tmp, "port")
    log = open(os.path.join(tmp, "umbrad.log"), "w")
    extra = os.environ.get("FIRST_UMBRAD_ARGS", "").split()
    d = subprocess.Popen([os.path.join(build, "umbrad"), "--listen", "127.0.0.1:0", "--port-file", port_file,
                          "--model-cache", "512M"] + extra, stdout=log, stderr=log)
    t0 = time.monotonic()
    while time.monotonic() - t0 < 180:
        if d.poll() is not None:
            raise RuntimeError("umbrad exited %d (see %s)" % (d.returncode, log.name))
        if os.path.exists(port_file) and os.path.getsize(port_file):
            port = int(open(port_file).read())
            try:
                c = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
                c.request("GET", "/readyz")
                if c.getresponse().status == 200:
                    return d, port
            except OSError:
                pass
        time.sleep(0.1)
    raise RuntimeError("umbrad not ready")


def turned(n):
    """objects[0]'s members for round n: a turn about +Y of (n + 1) hundredths of a degree."""
    a = math.radians(0.01 * (n + 1)) / 2
    return {"transform": {"rotation": [0.0, math.sin(a), 0.0, math.cos(a)]}}


def post(port, model, data, obj_extra=None):
    body, ctype = farm_bench.multipart(model, data, obj_extra)
    t0 = time.monotonic()
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=600)
    c.request("POST", "/v1/render", body=body, headers={"Content-Type": ctype})
    r = c.getresponse()
    r.read()
    ms = (time.monotonic() - t0) * 1000
    if r.status != 200:
        raise RuntimeError("%s: HTTP %d" % (model["file"], r.status))
    timing = farm_bench.parse_server_timing(r.getheader("Server-Timing"))
    c.close()
    return ms, timing


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    build, paths = sys.argv[1], sys.argv[2:]
    with tempfile.TemporaryDirectory() as tmp:
        daemon, port = start(build, tmp)
        rows, stages = [], []
        try:
            for path in paths:
                fmt = FORMATS[os.path.splitext(path)[1].lower()]
                model = {"file": os.path.basename(path), "format": fmt}
                data = open(path, "rb").read()
                first, warm = [], []
                for n in range(ROUNDS):
                    new = fresh(data, fmt, n)
                    first.append(post(port, model, new, turned(n)))
                    warm.append(post(port, model, new, turned(n)))
                med = lambda xs: statistics.median(xs)
                f_ms, w_ms = med([m for m, _ in first]), med([m for m, _ in warm])
                names = [k for k in first[0][1] if k not in ("total",)]
                for k in names:
                    if k not in stages:
                        stages.append(k)
                st = {k: med([t.get(k) or 0 for _, t in first]) for k in names}
                wst = {k: med([t.get(k) or 0 for _, t in warm]) for k in names}
                rows.append((model["file"], f_ms, min(m for m, _ in first), max(m for m, _ in first), w_ms, st, wst))
        finally:
            daemon.send_signal(signal.SIGTERM)
            daemon.wait(60)
    print("First requests of new models, one at a time, %d rounds (medians, ms; 'first' min-max; "
          "Server-Timing of the first request):" % ROUNDS)
    shown = [s for s in stages if any(r[5].get(s) for r in rows)]
    head = ["model", "first", "range", "warm", "first / warm"] + shown
    body = [[r[0], farm_bench.fmt_ms(r[1]), "%s-%s" % (farm_bench.fmt_ms(r[2]), farm_bench.fmt_ms(r[3])),
             farm_bench.fmt_ms(r[4]), "%.1f" % (r[1] / r[4])] + [farm_bench.fmt_ms(r[5].get(s)) for s in shown]
            for r in rows]
    print(farm_bench.table(head, body))
    print("\nThe warm requests' Server-Timing (medians, ms):")
    shown = [s for s in stages if any(r[6].get(s) for r in rows)]
    body = [[r[0], farm_bench.fmt_ms(r[4])] + [farm_bench.fmt_ms(r[6].get(s)) for s in shown] for r in rows]
    print(farm_bench.table(["model", "warm"] + shown, body))


if __name__ == "__main__":
    main()
