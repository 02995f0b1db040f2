#!/usr/bin/env python3
"""tests/clients/test_python.py URL — clients/python/umbra_client.py against a real umbrad at URL
(renders, a problem raised with its pointer, a conditional request, a model with its .mtl, WebP
by Accept) and against fake servers here (503 + Retry-After retried with the same body until
200, a 400 sent once, a refused connection given up). Prints ok/FAIL lines, then
"N passed, N failed"."""
import http.server, os, sys, tempfile, threading
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "clients", "python"))
from umbra_client import Client, UmbraError  # noqa: E402

URL = sys.argv[1]
passed = failed = 0


def check(name, cond, info=""):
    global passed, failed
    if cond:
        passed += 1
        print("ok - python: " + name)
    else:
        failed += 1
        print("FAIL - python: %s%s" % (name, (": " + str(info)) if info else ""))


SCENE = {"width": 48, "height": 32, "camera": {"position": [3, 2, 3], "target": [0, 0.5, 0]},
         "objects": [{"shape": "plane", "size": [4, 4]}, {"shape": "sphere", "transform": {"translation": [0, 0.6, 0]}}],
         "lights": [{"type": "directional", "direction": [-0.4, -1, -0.3]}]}
umbra = Client(URL)
r = umbra.render(SCENE)
check("render answers a PNG with an ETag", r.body[:8] == b"\x89PNG\r\n\x1a\n" and r.etag and r.attempts == 1,
      (r.content_type, r.etag))
check("render: Server-Timing read", "total" in r.server_timing or len(r.server_timing) > 2, r.server_timing)
again = umbra.render(SCENE, etag=r.etag)
check("the same scene with its ETag is not modified (no body)", again.not_modified and again.body is None,
      again.status)
try:
    umbra.render(dict(SCENE, lights=[{"type": "directional", "direction": [0, 0, 0]}]))
    check("a bad scene raises UmbraError", False)
except UmbraError as e:
    check("a bad scene raises UmbraError with the pointer", e.status == 400 and e.pointer == "/lights/0/direction"
          and "zero" in e.detail, e)
w = umbra.render(SCENE, accept="image/webp")
check("Accept image/webp answers WebP", w.content_type == "image/webp" and w.body[:4] == b"RIFF", w.content_type)
with tempfile.TemporaryDirectory() as d:
    with open(os.path.join(d, "tri.obj"), "w") as fh:
        fh.write("mtllib tri.mtl\nv -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nusemtl red\nf 1 2 3\n")
    with open(os.path.join(d, "tri.mtl"), "w") as fh:
        fh.write("newmtl red\nKd 1 0 0\n")
    m = umbra.render_model(os.path.join(d, "tri.obj"))
    check("render_model sends the .obj's .mtl (no warning)", m.body[:4] == b"\x89PNG" and not m.warnings, m.warnings)
    bare = umbra.render_model(os.path.join(d, "tri.obj"), files=[])
    check("without the .mtl the daemon names it", bare.warnings and "tri.mtl" in bare.warnings, bare.warnings)


# ---- fake servers ----
class Fake(http.server.BaseHTTPRequestHandler):
    script = []   # (status, headers, body) per request, the last repeated
    bodies = []

    def do_POST(self):
        n = int(self.headers.get("Content-Length", "0"))
        Fake.bodies.append(self.rfile.read(n))
        status, headers, body = Fake.script[min(len(Fake.bodies) - 1, len(Fake.script) - 1)]
        self.send_response(status)
        for k, v in headers.items():
            self.send_header(k, v)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *a):
        pass


srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Fake)
threading.Thread(target=srv.serve_forever, daemon=True).start()
fake = Client("http://127.0.0.1:%d" % srv.server_address[1], retries=5)
Fake.script = [(503, {"Retry-After": "0"}, b"{}"), (503, {"Retry-After": "0"}, b"{}"),
               (200, {"Content-Type": "image/png", "ETag": '"x"'}, b"\x89PNG fake")]
r = fake.render(SCENE)
check("503 + Retry-After retried until 200", r.attempts == 3 and r.body == b"\x89PNG fake", r.attempts)
check("every retry sends the same body", len(Fake.bodies) == 3 and len(set(Fake.bodies)) == 1, len(Fake.bodies))
Fake.bodies = []
Fake.script = [(400, {"Content-Type": "application/problem+json"},
                b'{"title":"Invalid scene","status":400,"detail":"bad","pointer":"/width"}')]
try:
    fake.render(SCENE)
    check("a 400 raises", False)
except UmbraError as e:
    check("a 400 is not retried and raises with its pointer", len(Fake.bodies) == 1 and e.pointer == "/width", e)
srv.shutdown()
gone = Client("http://127.0.0.1:%d" % srv.server_address[1], retries=1)
srv.server_close()
try:
    gone.render(SCENE)
    check("a refused connection raises", False)
except UmbraError as e:
    check("a refused connection is retried, then raises (status 0)", e.status == 0 and "cannot reach" in str(e), e)
print("%d passed, %d failed" % (passed, failed))
sys.exit(1 if failed else 0)
