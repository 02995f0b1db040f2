"""umbra_client — a small client for umbrad (Python 3.8+, standard library only).

Copy this file into a project, or put clients/python on PYTHONPATH:

    from umbra_client import Client, UmbraError
    umbra = Client("http://127.0.0.1:8080")
    png = umbra.render({"preset": "thumbnail", "objects": [{"shape": "sphere"}]}).body
    thumb = umbra.render_model("models/Avocado.gltf")          # sends Avocado.bin and its images too
    try:
        umbra.render({"camera": {"position": [0, 0, 0]}})
    except UmbraError as e:
        print(e.status, e.pointer, e.detail)                   # 400 /camera ... what to change

What it does for you:
- 503 and 429 are retried after `Retry-After` (at most `max_wait` seconds each), with jitter
  (x 1 to 1.5, so a fleet of clients does not come back at the same instant), up to `retries`
  times; a connection refused or reset, 502 or 504 (a balancer in front) likewise, with
  exponential back-off from 0.25 s. Renders are idempotent: a retried request renders the same
  bytes. Any other 4xx is raised at once as UmbraError, with the problem's pointer and detail.
- Conditional requests: pass the ETag of an image you have (`etag=`); when it still holds, the
  result has `not_modified = True` and no body (umbrad answers 304, or 412 to a POST).
- A model's files: a .gltf's buffers and images and an .obj's .mtl and textures are found
  beside it and sent as multipart parts named by their reference, as umbrad expects.
"""
import json
import os
import random
import re
import socket
import time
import urllib.error
import urllib.parse
import urllib.request
import uuid

__all__ = ["Client", "Result", "UmbraError"]


class UmbraError(Exception):
    """A 4xx/5xx from umbrad: its RFC 9457 problem (type, title, status, detail, pointer)."""

    def __init__(self, status, problem=None, message=None):
        self.status = status
        self.problem = problem or {}
        self.type = self.problem.get("type")
        self.title = self.problem.get("title")
        self.detail = self.problem.get("detail") or message or ""
        self.pointer = self.problem.get("pointer")
        where = " at %s" % self.pointer if self.pointer else ""
        super().__init__("%d %s%s: %s" % (status, self.title or "error", where, self.detail))


class Result:
    """An answer: body (bytes; None when not_modified), content_type, etag, warnings (the
    Umbra-Warnings header or None), server_timing (stage -> ms), attempts."""

    def __init__(self, status, headers, body, attempts):
        self.status = status
        self.not_modified = status in (304, 412)
        self.body = None if self.not_modified else body
        self.content_type = headers.get("Content-Type")
        self.etag = headers.get("ETag")
        self.warnings = headers.get("Umbra-Warnings")
        self.server_timing = {}
        for part in (headers.get("Server-Timing") or "").split(","):
            m = re.match(r"\s*([\w-]+)\s*;\s*dur=([\d.]+)", part)
            if m:
                self.server_timing[m.group(1)] = float(m.group(2))
        self.attempts = attempts


FORMATS = {".glb": "glb", ".gltf": "gltf", ".obj": "obj", ".stl": "stl", ".ply": "ply"}


def model_references(path):
    """The files a model refers to, as (reference as written, path on disk): a .gltf's
    buffers[].uri and images[].uri (not data: URIs), an .obj's mtllib files and the .mtl's map_*
    / bump / norm / disp textures. Missing files are left out (umbrad then names them)."""
    base = os.path.dirname(os.path.abspath(path))
    refs = []

    def add(ref, rel_to):
        if not ref or ref.startswith("data:") or "://" in ref:
            return
        p = os.path.normpath(os.path.join(rel_to, urllib.parse.unquote(ref.replace("\\", "/"))))
        if os.path.isfile(p) and ref not in [r for r, _ in refs]:
            refs.append((ref, p))

    ext = os.path.splitext(path)[1].lower()
    if ext == ".gltf":
        with open(path, "rb") as fh:
            doc = json.load(fh)
        for item in doc.get("buffers", []) + doc.get("images", []):
            add(item.get("uri"), base)
    elif ext == ".obj":
        with open(path, "r", errors="replace") as fh:
            mtls = [line.split(None, 1)[1].strip() for line in fh if line.startswith("mtllib ")]
        for mtl in mtls:
            add(mtl, base)
            p = os.path.join(base, mtl)
            if not os.path.isfile(p):
                continue
            with open(p, "r", errors="replace") as fh:
                for line in fh:
                    words = line.split()
                    if words and (words[0].startswith("map_") or words[0] in ("bump", "norm", "disp")):
                        add(words[-1], os.path.dirname(p))
    return refs


class Client:
    def __init__(self, url="http://127.0.0.1:8080", timeout=120, retries=8, max_wait=60, priority=None):
        self.url = url.rstrip("/")
        self.timeout = timeout
        self.retries = retries
        self.max_wait = max_wait
        self.priority = priority   # "interactive" or "bulk" (X-Priority), None: the daemon's default

    # ---- requests ----

    def info(self):
        """GET /v1/info as a dict."""
        return json.loads(self._send("GET", "/v1/info", None, {}).body)

    def render(self, scene, accept=None, etag=None, affinity=None):
        """POST /v1/render with a scene (a dict, or JSON text). accept: e.g. "image/webp"."""
        body = scene.encode() if isinstance(scene, str) else json.dumps(scene).encode()
        headers = {"Content-Type": "application/json"}
        return self._send("POST", "/v1/render", body, self._headers(headers, accept, etag, affinity))

    def render_model(self, path, scene=None, accept=None, etag=None, files=None):
        """A model file as a thumbnail (default scene: {"preset": "thumbnail"} with the model as
        its object), sent as multipart with the files it refers to (model_references, or
        `files`: a list of (reference, path))."""
        fmt = FORMATS.get(os.path.splitext(path)[1].lower())
        if scene is None:
            scene = {"preset": "thumbnail", "objects": [{"shape": "model", "part": "model"}]}
            if fmt:
                scene["objects"][0]["format"] = fmt
        parts = [("scene", "scene.json", "application/json", json.dumps(scene).encode())]
        with open(path, "rb") as fh:
            parts.append(("model", os.path.basename(path), "application/octet-stream", fh.read()))
        for ref, p in (files if files is not None else model_references(path)):
            with open(p, "rb") as fh:
                parts.append((ref, os.path.basename(p), "application/octet-stream", fh.read()))
        boundary = "umbra-" + uuid.uuid4().hex
        body = b"".join(b"--%s\r\nContent-Disposition: form-data; name=\"%s\"; filename=\"%s\"\r\n"
                        b"Content-Type: %s\r\n\r\n%s\r\n" % (boundary.encode(), n.encode(), f.encode(), t.encode(), d)
                        for n, f, t, d in parts) + b"--%s--\r\n" % boundary.encode()
        headers = {"Content-Type": "multipart/form-data; boundary=" + boundary}
        return self._send("POST", "/v1/render", body, self._headers(headers, accept, etag, None))

    # ---- the retry loop ----

    def _headers(self, headers, accept, etag, affinity):
        if accept:
            headers["Accept"] = accept
        if etag:
            headers["If-None-Match"] = etag
        if affinity:
            headers["X-Umbra-Affinity"] = affinity
        if self.priority:
            headers["X-Priority"] = self.priority
        return headers

    def _wait(self, seconds):
        time.sleep(min(seconds, self.max_wait) * random.uniform(1.0, 1.5))

    def _send(self, method, route, body, headers):
        attempt = 0
        while True:
            attempt += 1
            req = urllib.request.Request(self.url + route, data=body, method=method, headers=headers)
            try:
                with urllib.request.urlopen(req, timeout=self.timeout) as r:
                    return Result(r.status, r.headers, r.read(), attempt)
            except urllib.error.HTTPError as e:
                data = e.read()
                if e.code in (304, 412) and headers.get("If-None-Match"):
                    return Result(e.code, e.headers, b"", attempt)
                if e.code in (429, 503, 502, 504) and attempt <= self.retries:
                    ra = e.headers.get("Retry-After")
                    self._wait(float(ra) if ra and ra.strip().isdigit() else 0.25 * 2 ** min(attempt - 1, 5))
                    continue
                try:
                    problem = json.loads(data)
                except ValueError:
                    problem = None
                raise UmbraError(e.code, problem, data[:200].decode("utf-8", "replace")) from None
            except (urllib.error.URLError, ConnectionError, socket.timeout) as e:
                if attempt <= self.retries:
                    self._wait(0.25 * 2 ** min(attempt - 1, 5))
                    continue
                raise UmbraError(0, None, "cannot reach %s: %s" % (self.url, getattr(e, "reason", e))) from None
