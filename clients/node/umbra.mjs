// umbra.mjs — a small client for umbrad (Node 18+, built-in fetch, no dependencies).
//
//   import { Client, UmbraError } from "./umbra.mjs";
//   const umbra = new Client("http://127.0.0.1:8080");
//   const png = (await umbra.render({ preset: "thumbnail", objects: [{ shape: "sphere" }] })).body;
//   const thumb = await umbra.renderModel("models/Avocado.gltf");   // its .bin and images too
//   try { await umbra.render({ camera: { position: [0, 0, 0] } }); }
//   catch (e) { if (e instanceof UmbraError) console.log(e.status, e.pointer, e.detail); }
//
// What it does for you (fetch does none of it):
// - 503 and 429 are retried after Retry-After (at most maxWait seconds each) with jitter (x 1
//   to 1.5), up to `retries` times; a connection refused or reset, 502 or 504 likewise, with
//   exponential back-off from 0.25 s. Renders are idempotent. Any other 4xx throws UmbraError
//   at once, with the problem's pointer and detail.
// - Conditional requests: pass the ETag of an image you have ({ etag }); when it still holds
//   the result has notModified = true and no body (umbrad answers 304, or 412 to a POST).
// - A model's files: a .gltf's buffers and images and an .obj's .mtl and textures are found
//   beside it and sent as multipart parts named by their reference.
import { readFile } from "node:fs/promises";
import { existsSync, readFileSync, statSync } from "node:fs";
import path from "node:path";

export class UmbraError extends Error {
  constructor(status, problem, message) {
    const p = problem || {};
    const detail = p.detail || message || "";
    super(`${status} ${p.title || "error"}${p.pointer ? " at " + p.pointer : ""}: ${detail}`);
    this.name = "UmbraError";
    this.status = status;
    this.problem = p;
    this.type = p.type;
    this.title = p.title;
    this.detail = detail;
    this.pointer = p.pointer;
  }
}

const FORMATS = { ".glb": "glb", ".gltf": "gltf", ".obj": "obj", ".stl": "stl", ".ply": "ply" };

function timing(header) {
  const out = {};
  for (const part of (header || "").split(",")) {
    const m = /^\s*([\w-]+)\s*;\s*dur=([\d.]+)/.exec(part);
    if (m) out[m[1]] = Number(m[2]);
  }
  return out;
}

// The files a model refers to, as [reference as written, path on disk] (see the Python client).
export function modelReferences(file) {
  const base = path.dirname(path.resolve(file));
  const refs = [];
  const add = (ref, relTo) => {
    if (!ref || ref.startsWith("data:") || ref.includes("://")) return;
    const p = path.normalize(path.join(relTo, decodeURIComponent(ref.replaceAll("\\", "/"))));
    if (existsSync(p) && statSync(p).isFile() && !refs.some(([r]) => r === ref)) refs.push([ref, p]);
  };
  const ext = path.extname(file).toLowerCase();
  if (ext === ".gltf") {
    const doc = JSON.parse(readFileSync(file, "utf8"));
    for (const item of [...(doc.buffers || []), ...(doc.images || [])]) add(item.uri, base);
  } else if (ext === ".obj") {
    const mtls = readFileSync(file, "latin1").split(/\r?\n/).filter((l) => l.startsWith("mtllib ")).map((l) => l.slice(7).trim());
    for (const mtl of mtls) {
      add(mtl, base);
      const p = path.join(base, mtl);
      if (!existsSync(p)) continue;
      for (const line of readFileSync(p, "latin1").split(/\r?\n/)) {
        const w = line.trim().split(/\s+/);
        if (w[0] && (w[0].startsWith("map_") || ["bump", "norm", "disp"].includes(w[0]))) add(w[w.length - 1], path.dirname(p));
      }
    }
  }
  return refs;
}

export class Client {
  constructor(url = "http://127.0.0.1:8080", { timeout = 120, retries = 8, maxWait = 60, priority } = {}) {
    this.url = url.replace(/\/+$/, "");
    this.timeout = timeout;
    this.retries = retries;
    this.maxWait = maxWait;
    this.priority = priority; // "interactive" or "bulk" (X-Priority)
  }

  async info() {
    return JSON.parse(Buffer.from((await this.#send("GET", "/v1/info", undefined, {})).body).toString());
  }

  async render(scene, { accept, etag, affinity } = {}) {
    const body = typeof scene === "string" ? scene : JSON.stringify(scene);
    return this.#send("POST", "/v1/render", body, this.#headers({ "Content-Type": "application/json" }, accept, etag, affinity));
  }

  // A model file as a thumbnail (default scene: the thumbnail preset with the model as its
  // object), multipart with the files it refers to (modelReferences, or files: [[ref, path]]).
  async renderModel(file, { scene, accept, etag, files } = {}) {
    const fmt = FORMATS[path.extname(file).toLowerCase()];
    const s = scene || { preset: "thumbnail", objects: [{ shape: "model", part: "model", ...(fmt ? { format: fmt } : {}) }] };
    // A FormData is read once: a fresh one for every attempt.
    const parts = [["model", path.basename(file), await readFile(file)]];
    for (const [ref, p] of files || modelReferences(file)) parts.push([ref, path.basename(p), await readFile(p)]);
    const form = () => {
      const f = new FormData();
      f.append("scene", new Blob([JSON.stringify(s)], { type: "application/json" }), "scene.json");
      for (const [name, base, data] of parts) f.append(name, new Blob([data]), base);
      return f;
    };
    return this.#send("POST", "/v1/render", form, this.#headers({}, accept, etag));
  }

  #headers(h, accept, etag, affinity) {
    if (accept) h.Accept = accept;
    if (etag) h["If-None-Match"] = etag;
    if (affinity) h["X-Umbra-Affinity"] = affinity;
    if (this.priority) h["X-Priority"] = this.priority;
    return h;
  }

  #wait(seconds) {
    const ms = Math.min(seconds, this.maxWait) * (1 + Math.random() * 0.5) * 1000;
    return new Promise((r) => setTimeout(r, ms));
  }

  async #send(method, route, body, headers) {
    for (let attempt = 1; ; attempt++) {
      let r;
      try {
        r = await fetch(this.url + route, {
          method, headers, body: typeof body === "function" ? body() : body,
          signal: AbortSignal.timeout(this.timeout * 1000),
        });
      } catch (e) {
        if (attempt <= this.retries) { await this.#wait(0.25 * 2 ** Math.min(attempt - 1, 5)); continue; }
        throw new UmbraError(0, null, `cannot reach ${this.url}: ${e.cause?.code || e.message}`);
      }
      const data = new Uint8Array(await r.arrayBuffer());
      if (r.ok || ((r.status === 304 || r.status === 412) && headers["If-None-Match"])) {
        const notModified = r.status === 304 || r.status === 412;
        return {
          status: r.status, notModified, body: notModified ? null : data, contentType: r.headers.get("content-type"),
          etag: r.headers.get("etag"), warnings: r.headers.get("umbra-warnings"),
          serverTiming: timing(r.headers.get("server-timing")), attempts: attempt,
        };
      }
      if ([429, 502, 503, 504].includes(r.status) && attempt <= this.retries) {
        const ra = r.headers.get("retry-after");
        await this.#wait(ra && /^\d+$/.test(ra.trim()) ? Number(ra) : 0.25 * 2 ** Math.min(attempt - 1, 5));
        continue;
      }
      let problem = null;
      try { problem = JSON.parse(Buffer.from(data).toString()); } catch { /* not JSON */ }
      throw new UmbraError(r.status, problem, Buffer.from(data.slice(0, 200)).toString());
    }
  }
}
