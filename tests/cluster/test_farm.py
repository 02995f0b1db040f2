#!/usr/bin/env python3
"""tests/cluster/test_farm.py — umbra-render thumb --server: the farm on real daemons.

    BUILD=build python3 tests/cluster/test_farm.py        (tests/run.sh: suite farm-remote)

Models are generated here (tests/cli/gen_models.py, plus an .obj with its .mtl and a .gltf with
its .bin, so the files a model refers to travel as parts). Checked:
  - the remote farm (three umbrad behind HAProxy, deploy/cluster.py) gives the local farm's
    bytes, statuses and content hashes for every input;
  - SIGINT (and SIGKILL) mid-run then --resume: every input ok, nothing rendered in both runs; a local
    --resume renders nothing, and a changed model (new hash) is rendered again;
  - --shard K/3: the three shards cover every input exactly once;
  - a bad scene is `invalid` with the same problem text (status, pointer, detail) as locally;
  - one daemon SIGKILLed (and restarted on its port) and one SIGTERMed while the farm runs:
    every input ok, one line each, the local bytes;
  - against a fake server: 503 + Retry-After then 200 (retried), 502 (bounded retries then
    failed), 400 (invalid, sent once), X-Umbra-Affinity = the report's hash.
Faults are driven by the farm's progress lines, never by time. Prints "ok - x" / "FAIL - x" and
last "N passed, N failed".
"""
import http.server
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "deploy"))
import cluster  # noqa: E402

BUILD = os.environ.get("BUILD", "build")
CLI = os.path.join(BUILD, "umbra-render")
ENV = dict(os.environ)
if os.environ.get("DAEMON_PRELOAD"):
    ENV["LD_PRELOAD"] = os.environ["DAEMON_PRELOAD"]
N_MODELS = 30
SIZE = "64"
passed = failed = 0


def ok(name, cond, detail=""):
    global passed, failed
    if cond:
        passed += 1
        print("ok - %s" % name)
    else:
        failed += 1
        print("FAIL - %s%s" % (name, ": " + str(detail)[:600] if detail else ""))
    sys.stdout.flush()
    return cond


def write_refs_models(d):
    """An .obj with its .mtl, and a .gltf with its .bin (a box), so models carry other files."""
    with open(os.path.join(d, "crate.mtl"), "w") as f:
        f.write("newmtl red\nKd 0.8 0.1 0.1\n")
    with open(os.path.join(d, "crate.obj"), "w") as f:
        f.write("mtllib crate.mtl\nusemtl red\n")
        for x, y, z in [(-1, 0, -1), (1, 0, -1), (1, 1, -1), (-1, 1, -1), (-1, 0, 1), (1, 0, 1), (1, 1, 1), (-1, 1, 1)]:
            f.write("v %d %d %d\n" % (x, y, z))
        f.write("f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n")
    pos = [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1), (-1, 0, 1), (1, 0, 1), (1, 2, 1), (-1, 2, 1)]
    idx = [0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5]
    pb = b"".join(struct.pack("<3f", *p) for p in pos)
    ib = b"".join(struct.pack("<H", i) for i in idx)
    with open(os.path.join(d, "tower.bin"), "wb") as f:
        f.write(pb + ib)
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "buffers": [{"uri": "tower.bin", "byteLength": len(pb) + len(ib)}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pb)},
                            {"buffer": 0, "byteOffset": len(pb), "byteLength": len(ib)}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
                           "min": [-1, 0, -1], "max": [1, 2, 1]},
                          {"bufferView": 1, "componentType": 5123, "count": len(idx), "type": "SCALAR"}]}
    with open(os.path.join(d, "tower.gltf"), "w") as f:
        json.dump(gltf, f)


def models(tmp):
    d = os.path.join(tmp, "models")
    subprocess.run([sys.executable, os.path.join(ROOT, "tests/cli/gen_models.py"), d, str(N_MODELS - 2)], check=True)
    write_refs_models(d)
    return sorted(os.path.join(d, f) for f in os.listdir(d) if f.rsplit(".", 1)[-1] in ("obj", "stl", "ply", "gltf"))


def farm(inputs, out, *extra, stop_after=None, on_line=None, timeout=600, sig=signal.SIGINT):
    """Runs umbra-render thumb; stop_after=k sends sig (SIGINT) after k progress lines; on_line(n)
    is called after each. Returns (exit code, stderr text, report lines)."""
    cmd = [CLI, "thumb"] + inputs + ["-o", out, "--size", SIZE, "--no-progress"] + list(extra)
    p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         env=ENV, text=True)
    lines, n = [], 0
    for line in p.stderr:
        lines.append(line)
        if line.startswith("umbra-render: ["):
            n += 1
            if stop_after is not None and n == stop_after:
                p.send_signal(sig)
            if on_line:
                on_line(n)
    code = p.wait(timeout)
    return code, "".join(lines), report(out, extra)


def report(out, extra=()):
    path = os.path.join(out, "report.jsonl")
    if "--report" in extra:
        path = extra[list(extra).index("--report") + 1]
    elif "--shard" in extra:
        k, n = extra[list(extra).index("--shard") + 1].split("/")
        path = os.path.join(out, "report-%s-of-%s.jsonl" % (k, n))
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return []
    lines = []
    for l in text.splitlines():
        try:
            lines.append(json.loads(l))
        except ValueError:
            lines.append({"file": None, "status": "cut line"})
    return lines


def read(path):
    with open(path, "rb") as f:
        return f.read()


def same_images(lines, ref):
    """Files whose output differs from the local farm's (ref: file -> bytes)."""
    return [l["file"] for l in lines if l["status"] != "ok" or read(l["output"]) != ref.get(l["file"])]


# ---- against the fake server ----

class Fake(http.server.BaseHTTPRequestHandler):
    script = []      # answers in order: (status, headers, body); the last repeats
    seen = []        # (path, headers) of every request

    def do_POST(self):
        self.rfile.read(int(self.headers.get("Content-Length", 0)))
        Fake.seen.append((self.path, dict(self.headers)))
        status, headers, body = Fake.script[min(len(Fake.seen) - 1, len(Fake.script) - 1)]
        self.send_response(status)
        for k, v in headers.items():
            self.send_header(k, v)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *a):
        pass


def fake_checks(tmp, inputs):
    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Fake)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    url = "http://127.0.0.1:%d" % srv.server_address[1]
    png = read(os.path.join(tmp, "local", os.path.basename(inputs[0]).rsplit(".", 1)[0] + ".png"))
    one = inputs[:1]
    busy = (503, {"Retry-After": "0", "Content-Type": "application/problem+json"},
            b'{"type":"about:blank","title":"Service Unavailable","status":503,"detail":"queue full","pointer":""}')
    Fake.script, Fake.seen = [busy, busy, (200, {"Content-Type": "image/png"}, png)], []
    code, err, lines = farm(one, os.path.join(tmp, "fake1"), "--server", url)
    ok("503 + Retry-After is retried until the 200 (3 requests)", code == 0 and len(Fake.seen) == 3 and
       lines and lines[0]["status"] == "ok" and lines[0].get("attempts") == 3, (code, len(Fake.seen), lines, err))
    ok("the retried answer is written as it came", lines and read(lines[0]["output"]) == png)
    aff = [h.get("X-Umbra-Affinity") for _, h in Fake.seen]
    ok("X-Umbra-Affinity is the model's content hash, the same on every try",
       lines and aff == [lines[0].get("hash")] * 3, (aff, lines))
    Fake.script, Fake.seen = [(502, {"Content-Type": "text/html"}, b"<html>502 Bad Gateway</html>")], []
    code, err, lines = farm(one, os.path.join(tmp, "fake2"), "--server", url)
    ok("502 is retried a bounded number of times, then failed (exit 1)", code == 1 and len(Fake.seen) == 5 and
       lines and lines[0]["status"] == "failed", (code, len(Fake.seen), lines))
    bad = (400, {"Content-Type": "application/problem+json"},
           b'{"type":"x","title":"Invalid scene","status":400,"detail":"must be positive","pointer":"/width"}')
    Fake.script, Fake.seen = [bad], []
    code, err, lines = farm(one, os.path.join(tmp, "fake3"), "--server", url)
    ok("a 400 is invalid (exit 2) with its pointer and detail, sent once", code == 2 and len(Fake.seen) == 1 and
       lines and lines[0]["status"] == "invalid" and "/width: must be positive" in (lines[0]["error"] or ""),
       (code, len(Fake.seen), lines))
    srv.shutdown()
    srv.server_close()
    code, err, lines = farm(one, os.path.join(tmp, "fake4"), "--server", url)   # nobody listens now
    ok("a refused connection is failed after the retries (exit 1)", code == 1 and lines and
       lines[0]["status"] == "failed" and "connect" in (lines[0]["error"] or ""), (code, lines))


# ---- against three daemons behind HAProxy ----

def remote_equals_local(c, tmp, inputs, ref, local):
    code, err, lines = farm(inputs, os.path.join(tmp, "remote"), "--server", c.url, "-j", "6")
    ok("remote farm exits 0 with every input ok", code == 0 and len(lines) == len(inputs) and
       all(l["status"] == "ok" for l in lines), (code, err[-400:]))
    diff = same_images(lines, ref)
    ok("remote PNGs are the local farm's bytes (%d models)" % len(inputs), not diff, diff[:5])
    lh = {l["file"]: l["hash"] for l in local}
    ok("remote and local reports carry the same content hashes",
       all(lh.get(l["file"]) == l.get("hash") for l in lines))
    ok("report has the daemons' stages", all("main" in (l.get("stages") or {}) for l in lines), lines[:1])
    rows = {r["pxname"]: int(r.get("stot") or 0) for r in c.stats_rows() if r.get("svname") == "BACKEND"}
    ok("every request went by X-Umbra-Affinity (HAProxy's consistent-hash backend)",
       rows.get("umbrad_affinity", 0) >= len(inputs) and rows.get("umbrad", -1) == 0, rows)


def scenes_same(c, tmp):
    """Scenes through a manifest: an EXR scene by its own format and named .png (the name wins)."""
    scene = {"width": 48, "height": 48, "objects": [{"shape": "plane", "size": [8, 8]}, {"shape": "sphere", "radius": 1,
             "transform": {"translation": [0, 1, 0]}}], "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3],
             "color": [1, 1, 1], "intensity": 3}], "output": {"format": "exr"},
             "camera": {"type": "perspective", "position": [4, 3, 4], "target": [0, 0.5, 0], "up": [0, 1, 0], "fov_y": 40}}
    with open(os.path.join(tmp, "exr.json"), "w") as f:
        json.dump(scene, f)
    with open(os.path.join(tmp, "jobs.jsonl"), "w") as f:
        f.write('{"scene": "exr.json"}\n{"scene": "exr.json", "output": "named.png"}\n')
    outs = []
    for extra in ([], ["--server", c.url]):
        out = os.path.join(tmp, "scenes-%d" % len(outs))
        p = subprocess.run([CLI, "--manifest", os.path.join(tmp, "jobs.jsonl"), "-o", out, "--no-progress"] + extra,
                           capture_output=True, text=True, env=ENV, timeout=300)
        outs.append((p.returncode, [(os.path.basename(l["output"] or ""), read(l["output"]) if l["output"] else b"")
                                    for l in report(out)]))
    names = [n for n, _ in outs[0][1]]
    ok("scenes by --server: an EXR scene, and named .png, are the local farm's files and bytes",
       outs[0] == outs[1] and outs[0][0] == 0 and names == ["exr.exr", "named.png"] and
       outs[0][1][1][1][:4] == b"\x89PNG", (outs[0][0], outs[1][0], names, [n for n, _ in outs[1][1]]))


def interrupt_resume(c, tmp, inputs, ref):
    out = os.path.join(tmp, "resume")
    code, err, first = farm(inputs, out, "--server", c.url, "-j", "2", stop_after=4)
    done1 = {l["file"] for l in first if l["status"] == "ok"}
    ok("SIGINT stops the remote farm (exit 130), the rest skipped", code == 130 and done1 and
       len(done1) < len(inputs) and all(l["status"] in ("ok", "skipped") for l in first),
       (code, len(done1), err[-300:]))
    code, err, second = farm(inputs, out, "--server", c.url, "-j", "2", "--resume")
    resumed = {l["file"] for l in second if l.get("resumed")}
    rendered = {l["file"] for l in second if l["status"] == "ok" and not l.get("resumed")}
    ok("--resume completes every input (exit 0)", code == 0 and len(second) == len(inputs) and
       all(l["status"] == "ok" for l in second), (code, err[-300:]))
    ok("--resume skips exactly what the first run made, renders the rest once",
       resumed == done1 and not (rendered & done1) and (resumed | rendered) == set(inputs),
       "%d resumed, %d rendered, %d first" % (len(resumed), len(rendered), len(done1)))
    ok("resumed and rendered outputs are the local bytes", not same_images(second, ref))


def killed_resume(c, tmp, inputs, ref):
    """SIGKILL, not Ctrl-C: the report is then the journal of what finished; --resume uses it."""
    out = os.path.join(tmp, "killed")
    code, err, first = farm(inputs, out, "--server", c.url, "-j", "2", stop_after=5, sig=signal.SIGKILL)
    done1 = {l["file"] for l in first if l["status"] == "ok"}
    ok("a SIGKILLed farm leaves a line per finished input", code == -signal.SIGKILL and len(done1) >= 5 and
       len(done1) < len(inputs) and all(l["status"] == "ok" for l in first), (code, len(done1), first[-2:]))
    code, err, second = farm(inputs, out, "--server", c.url, "-j", "2", "--resume")
    resumed = {l["file"] for l in second if l.get("resumed")}
    rendered = {l["file"] for l in second if l["status"] == "ok" and not l.get("resumed")}
    ok("--resume after SIGKILL: what was done kept, the rest rendered once, all ok",
       code == 0 and resumed == done1 and not (rendered & done1) and (resumed | rendered) == set(inputs) and
       len(second) == len(inputs), "%d resumed, %d rendered, %d first, exit %d" %
       (len(resumed), len(rendered), len(done1), code))
    ok("... the local bytes", not same_images(second, ref))


def local_resume(tmp, inputs, ref):
    out = os.path.join(tmp, "local")
    code, err, lines = farm(inputs, out, "-j", "2", "--resume")
    ok("local --resume renders nothing when all is done",
       code == 0 and len(lines) == len(inputs) and all(l.get("resumed") for l in lines), (code, err[-300:]))
    victim = [p for p in inputs if p.endswith(".obj") and "crate" not in p][0]
    with open(victim, "a") as f:
        f.write("v 0 9 0\n")   # new bytes: a new hash
    code, err, lines = farm(inputs, out, "-j", "2", "--resume")
    again = [l["file"] for l in lines if not l.get("resumed")]
    ok("local --resume renders again only the model whose bytes changed", code == 0 and again == [victim],
       (code, again))
    ref[victim] = read([l["output"] for l in lines if l["file"] == victim][0])


def shards(c, tmp, inputs, ref):
    out = os.path.join(tmp, "shards")
    seen = []
    codes = []
    for k in range(3):
        code, err, lines = farm(inputs, out, "--server", c.url, "-j", "4", "--shard", "%d/3" % k)
        codes.append(code)
        seen += lines
    files = [l["file"] for l in seen]
    ok("--shard K/3: three shards cover every input exactly once", codes == [0, 0, 0] and
       sorted(files) == sorted(inputs), (codes, len(files), len(set(files))))
    ok("--shard K/3 outputs are the local bytes", not same_images(seen, ref))
    code, err, _ = farm(inputs[:1], out, "--shard", "3/3")
    ok("--shard 3/3 is refused with a clear message", code == 1 and "--shard" in err, err[-200:])


def invalid_same_as_local(c, tmp):
    bad = os.path.join(tmp, "bad.json")
    with open(bad, "w") as f:
        json.dump({"width": -1, "objects": [{"shape": "sphere"}]}, f)
    errs = []
    for extra in ([], ["--server", c.url]):
        out = os.path.join(tmp, "bad-" + str(len(errs)))
        p = subprocess.run([CLI, bad, bad, "-o", out, "--no-progress"] + extra, capture_output=True, text=True,
                           env=ENV, timeout=300)
        lines = report(out)
        errs.append((p.returncode, [l["status"] for l in lines], lines[0]["error"] if lines else None))
    ok("a bad scene is invalid (exit 2) remotely with the local problem text (pointer, detail)",
       errs[0] == errs[1] and errs[0][0] == 2 and "/width" in (errs[0][2] or ""), errs)


def daemons_die(c, tmp, inputs, ref):
    restarted = []

    def restart_killed():
        c.daemons[0].wait(30)
        try:
            c.restart(0)
            restarted.append(True)
        except Exception as e:  # reported by the check below
            restarted.append(e)

    def faults(n):
        if n == 6:
            c.kill(0, signal.SIGKILL)
            # Restarted on its port while the farm goes on (off the line reader: its warm-up
            # takes seconds); whether it serves any of this farm's renders is not asserted.
            t = threading.Thread(target=restart_killed, daemon=True)
            t.start()
            restarter.append(t)
        elif n == 12:
            c.kill(1, signal.SIGTERM)
    restarter = []
    code, err, lines = farm(inputs, os.path.join(tmp, "faults"), "--server", c.url, "-j", "4", on_line=faults)
    for t in restarter:
        t.join(300)
    ok("the SIGKILLed daemon restarts on its port and is UP again",
       restarted == [True] and c.wait_status({c.daemons[0].name: "UP"}, 60), restarted)
    files = [l["file"] for l in lines]
    ok("a daemon SIGKILLed and one SIGTERMed mid-run: every input ok (exit 0)", code == 0 and
       all(l["status"] == "ok" for l in lines), (code, [l for l in lines if l["status"] != "ok"][:3], err[-400:]))
    ok("... each input once in the report, none lost", sorted(files) == sorted(inputs), len(files))
    ok("... with the local farm's bytes", not same_images(lines, ref))
    ok("the SIGTERMed daemon drained and exited 0", c.daemons[1].wait(90) == 0)
    tries = sum(l.get("attempts", 1) - 1 for l in lines)
    print("# %d farm retries through the faults; balancer retries %d, redispatches %d" %
          (tries, c.backend_total("wretr"), c.backend_total("wredis")))


def main():
    for exe in ("umbra-render", "umbrad"):
        if not os.access(os.path.join(BUILD, exe), os.X_OK):
            ok("%s built" % exe, False)
            print("%d passed, %d failed" % (passed, failed))
            return 1
    tmp = tempfile.mkdtemp(prefix="umbra-farm-test.")
    inputs = models(tmp)
    code, err, local = farm(inputs, os.path.join(tmp, "local"), "-j", "2")
    ok("local farm renders the %d generated models" % len(inputs), code == 0 and len(local) == len(inputs) and
       all(l["status"] == "ok" and len(l.get("hash", "")) == 16 for l in local), (code, err[-400:]))
    ref = {l["file"]: read(l["output"]) for l in local if l["status"] == "ok"}
    fake_checks(tmp, inputs)
    os.makedirs(os.path.join(tmp, "cluster"))
    c = cluster.Cluster(build=BUILD, daemons=3, port=0, stats_port=0, workdir=os.path.join(tmp, "cluster"), env=ENV)
    try:
        c.start()
        ok("three daemons UP behind haproxy", True)
        remote_equals_local(c, tmp, inputs, ref, local)
        invalid_same_as_local(c, tmp)
        scenes_same(c, tmp)
        interrupt_resume(c, tmp, inputs, ref)
        killed_resume(c, tmp, inputs, ref)
        local_resume(tmp, inputs, ref)
        shards(c, tmp, inputs, ref)
        daemons_die(c, tmp, inputs, ref)
    except cluster.ClusterError as e:
        ok("three daemons UP behind haproxy", False, str(e))
    finally:
        c.stop()
        if failed:
            print("# files kept in %s" % tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
