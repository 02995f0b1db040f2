#!/usr/bin/env python3
"""tests/http/soak.py PORT PID N ASSETS — N mixed requests against one umbrad, with its RSS and
open descriptors sampled as it goes.

The mix (fixed by a seeded generator, so runs are comparable): small renders (64², 128²), a few
bigger ones (1024² MSAA 4 every 500th request, 4096² with a 4096 shadow map every 2500th from the 500th:
the warm-up sees every kind of request once), bad JSON, 404s, 405s, /metrics, /readyz,
/healthz and /v1/info by GET and HEAD, multipart renders with a small OBJ model, a framing error,
and aborted connections (closed mid-body, or closed before the answer). Requests go over one
keep-alive connection (http.client) that is reopened whenever the daemon closes it; the raw
ones (aborts, framing) use their own sockets.

Every answer is checked: the expected status, one status line, PNG bytes for renders, a
problem+json body for errors. Every `SAMPLE` requests the daemon's VmRSS and its number of open
descriptors are recorded (the client's keep-alive connection is closed first, so the count
is the daemon's own). After the run: the daemon must be alive, the last sample of each within
its margin of the sample taken after the warm-up (the first WARM requests), and no answer
malformed. Prints the samples, "ok - ..." / "FAIL - ..." lines, and "N passed, N failed".
Env: SOAK_RSS_MARGIN_KB (default 65536), SOAK_FD_MARGIN (default 4), SOAK_SEED.
"""
import http.client
import json
import os
import random
import socket
import sys
import time

PORT, PID, N, ASSETS = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
SAMPLE = max(N // 20, 50)
# The warm-up ends once every kind of request has been seen (the first 4096² render is the
# 500th): 1,000 requests for long runs, 60 % of a short one.
WARM = 1000 if N >= 5000 else N * 3 // 5
RSS_MARGIN_KB = int(os.environ.get("SOAK_RSS_MARGIN_KB", "65536"))
FD_MARGIN = int(os.environ.get("SOAK_FD_MARGIN", "4"))
rng = random.Random(int(os.environ.get("SOAK_SEED", "10")))


def scene(w, h, msaa=1, res=512, segments=32, extra=""):
    return ('{"width": %d, "height": %d, "camera": {"type": "perspective", "position": [4, 3, 4],'
            ' "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y": 40},'
            ' "materials": {"grey": {"base_color": [0.7, 0.7, 0.7], "roughness": 0.8, "metallic": 0}},'
            ' "objects": [%s{"shape": "plane", "size": [10, 10], "material": "grey"},'
            ' {"shape": "sphere", "radius": 1, "segments": %d, "material": "grey",'
            ' "transform": {"translation": [0, 1, 0]}}],'
            ' "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3], "intensity": 3,'
            ' "shadow": {"filter": "pcf"}}], "shadows": {"resolution": %d}, "output": {"msaa": %d}}'
            % (w, h, extra, segments, res, msaa)).encode()


# Small scenes vary by a seeded member so some hit caches and some do not.
SMALL = [scene(64, 64, segments=16 + 8 * i) for i in range(4)] + [scene(64, 48)]
MEDIUM = [scene(128, 128, segments=24), scene(128, 128, msaa=4)]
BIG = scene(1024, 1024, msaa=4, res=2048, segments=128)
HUGE = scene(4096, 4096, res=4096, segments=64)
MODEL = scene(64, 64, extra='{"shape": "model", "part": "mesh", "format": "obj"}, ')
OBJ = b"v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n"
BOUNDARY = "soak-boundary-7c1f"


def multipart():
    parts = []
    for name, ctype, data in (("scene", "application/json", MODEL), ("mesh", "application/octet-stream", OBJ)):
        parts.append(("--%s\r\nContent-Disposition: form-data; name=\"%s\"; filename=\"%s\"\r\n"
                      "Content-Type: %s\r\n\r\n" % (BOUNDARY, name, name, ctype)).encode() + data + b"\r\n")
    return b"".join(parts) + ("--%s--\r\n" % BOUNDARY).encode()


MULTIPART = multipart()
JSON = {"Content-Type": "application/json"}

# (weight, kind) — kinds are handled in one()
MIX = [(34, "small"), (12, "medium"), (8, "badjson"), (6, "notfound"), (2, "method"), (7, "metrics"),
       (7, "readyz"), (5, "head"), (4, "info"), (6, "multipart"), (3, "abort"), (2, "framing"),
       (2, "unknownmember")]
KINDS = [k for w, k in MIX for _ in range(w)]


class Client:
    def __init__(self):
        self.c = None

    def close(self):
        if self.c:
            self.c.close()
        self.c = None

    def request(self, method, path, body=None, headers=None):
        for attempt in range(2):
            if self.c is None:
                self.c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=120)
            try:
                self.c.request(method, path, body=body, headers=headers or {})
                r = self.c.getresponse()
                data = r.read()
                if r.getheader("Connection", "").lower() == "close" or r.will_close:
                    self.close()
                return r, data
            except (http.client.RemoteDisconnected, ConnectionResetError, BrokenPipeError):
                # The daemon closed an idle keep-alive connection between requests: retry once
                # on a new one (only a request never answered is retried).
                self.close()
                if attempt:
                    raise
        raise RuntimeError("unreachable")


def is_problem(r, data, status):
    if r.status != status or not (r.getheader("Content-Type") or "").startswith("application/problem+json"):
        return False
    try:
        d = json.loads(data)
    except ValueError:
        return False
    return d.get("status") == status and all(k in d for k in ("type", "title", "detail", "pointer"))


def is_png(r, data):
    return r.status == 200 and r.getheader("Content-Type") == "image/png" and data[:8] == b"\x89PNG\r\n\x1a\n"


def raw(data, read=True):
    s = socket.create_connection(("127.0.0.1", PORT), timeout=60)
    try:
        s.sendall(data)
        out = b""
        while read:
            d = s.recv(65536)
            if not d:
                break
            out += d
        return out
    finally:
        s.close()


def one(cl, i, kind):
    """Sends request i of `kind`; returns None when its answer is right, else why not."""
    if i % 2500 == 500:
        r, d = cl.request("POST", "/v1/render", HUGE, JSON)
        return None if is_png(r, d) else "4096² render %d %r" % (r.status, d[:120])
    if i % 500 == 250:
        r, d = cl.request("POST", "/v1/render", BIG, JSON)
        return None if is_png(r, d) else "big render %d %r" % (r.status, d[:120])
    if kind == "small":
        r, d = cl.request("POST", "/v1/render", rng.choice(SMALL), JSON)
        return None if is_png(r, d) else "small render %d %r" % (r.status, d[:120])
    if kind == "medium":
        hdrs = dict(JSON)
        if rng.random() < 0.2:
            hdrs["X-Priority"] = "bulk"
        r, d = cl.request("POST", "/v1/render", rng.choice(MEDIUM), hdrs)
        return None if is_png(r, d) else "medium render %d %r" % (r.status, d[:120])
    if kind == "badjson":
        r, d = cl.request("POST", "/v1/render", SMALL[0][: rng.randrange(1, len(SMALL[0]) - 1)], JSON)
        return None if is_problem(r, d, 400) else "bad JSON %d %r" % (r.status, d[:120])
    if kind == "unknownmember":
        r, d = cl.request("POST", "/v1/render", SMALL[0].replace(b'"fov_y"', b'"fov"'), JSON)
        return None if is_problem(r, d, 400) else "unknown member %d %r" % (r.status, d[:120])
    if kind == "notfound":
        r, d = cl.request(rng.choice(["GET", "POST"]), "/v2/%d" % i, b"{}", JSON)
        return None if is_problem(r, d, 404) else "404 %d %r" % (r.status, d[:120])
    if kind == "method":
        r, d = cl.request("GET", "/v1/render")
        return None if is_problem(r, d, 405) and r.getheader("Allow") == "POST" else "405 %d" % r.status
    if kind == "metrics":
        r, d = cl.request("GET", "/metrics")
        return None if r.status == 200 and b"umbra_requests_total" in d else "metrics %d" % r.status
    if kind == "readyz":
        r, d = cl.request(rng.choice(["GET", "HEAD"]), "/readyz")
        return None if r.status == 200 else "readyz %d" % r.status
    if kind == "head":
        path = rng.choice(["/healthz", "/v1/info", "/metrics"])
        r, d = cl.request("HEAD", path)
        return None if r.status == 200 and d == b"" else "HEAD %s %d %r" % (path, r.status, d[:50])
    if kind == "info":
        r, d = cl.request("GET", "/v1/info")
        return None if r.status == 200 and json.loads(d).get("name") == "umbrad" else "info %d" % r.status
    if kind == "multipart":
        r, d = cl.request("POST", "/v1/render", MULTIPART,
                          {"Content-Type": "multipart/form-data; boundary=" + BOUNDARY})
        return None if is_png(r, d) else "multipart %d %r" % (r.status, d[:120])
    if kind == "abort":
        body = rng.choice(SMALL)
        if rng.random() < 0.5:  # closed mid-body
            raw(b"POST /v1/render HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
                b"Content-Length: %d\r\n\r\n" % len(body) + body[: len(body) // 2], read=False)
        else:  # whole request, closed before the answer
            raw(b"POST /v1/render HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
                b"Content-Length: %d\r\n\r\n" % len(body) + body, read=False)
        return None
    if kind == "framing":
        a = raw(b"POST /v1/render HTTP/1.1\r\nHost: localhost\r\nContent-Type: application/json\r\n"
                b"Content-Length: 10\r\nContent-Length: 11\r\n\r\n{}")
        head, _, body = a.partition(b"\r\n\r\n")
        ok = head.startswith(b"HTTP/1.1 400 ") and b"application/problem+json" in head and a.count(b"\r\nHTTP/1.") == 0
        return None if ok else "framing %r" % a[:200]
    return "unknown kind " + kind


def sample(n):
    with open("/proc/%d/status" % PID) as f:
        rss = next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
    return n, rss, len(os.listdir("/proc/%d/fd" % PID))


def settle(cl):
    """Closes the client's connection and waits (bounded) for the daemon to drop it."""
    cl.close()
    time.sleep(0.2)


def main():
    cl = Client()
    samples = [sample(0)]
    bad = []
    t0 = time.monotonic()
    for i in range(1, N + 1):
        kind = rng.choice(KINDS)
        try:
            why = one(cl, i, kind)
        except Exception as e:  # a dropped connection or a parse failure is a malformed answer
            cl.close()
            why = "%s: %r" % (kind, e)
        if why:
            bad.append("#%d %s" % (i, why))
        if i in (499, 501) or i % SAMPLE == 0 or i == WARM:
            settle(cl)
            samples.append(sample(i))
    secs = time.monotonic() - t0
    settle(cl)
    final = sample(N)
    print("# %d requests in %.1f s (%.0f/s)" % (N, secs, N / secs))
    print("# requests  VmRSS_KiB  fds")
    for n, rss, fds in samples + [final]:
        print("# %8d %10d %5d" % (n, rss, fds))
    warm = next(s for s in samples if s[0] == WARM)
    peak_rss = max(s[1] for s in samples if s[0] >= WARM)
    results = []

    def check(name, ok, why=""):
        results.append(ok)
        print(("ok - " if ok else "FAIL - ") + name + ("" if ok or not why else ": " + why))

    for b in bad[:20]:
        print("# " + b)
    check("soak: all %d answers well-formed and as expected" % N, not bad, "%d bad" % len(bad))
    check("soak: RSS flat after %d requests (last %d KiB, peak %d KiB, within %d KiB of %d KiB)"
          % (WARM, final[1], peak_rss, RSS_MARGIN_KB, warm[1]), final[1] <= warm[1] + RSS_MARGIN_KB)
    check("soak: open descriptors flat after %d requests (%d -> %d, margin %d)" % (WARM, warm[2], final[2], FD_MARGIN),
          final[2] <= warm[2] + FD_MARGIN)
    print("%d passed, %d failed" % (results.count(True), results.count(False)))
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
