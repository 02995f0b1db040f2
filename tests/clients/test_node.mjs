// tests/clients/test_node.mjs URL — clients/node/umbra.mjs against a real umbrad at URL and
// against fake servers here, the same checks as test_python.py. Prints ok/FAIL lines, then
// "N passed, N failed".
import http from "node:http";
import { mkdtempSync, writeFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { Client, UmbraError } from "../../clients/node/umbra.mjs";

const URL = process.argv[2];
let passed = 0, failed = 0;
const check = (name, cond, info = "") => {
  if (cond) { passed++; console.log("ok - node: " + name); }
  else { failed++; console.log(`FAIL - node: ${name}${info !== "" ? ": " + JSON.stringify(info) : ""}`); }
};
const isPng = (b) => b && b[0] === 0x89 && b[1] === 0x50 && b[2] === 0x4e && b[3] === 0x47;

const SCENE = {
  width: 48, height: 32, camera: { position: [3, 2, 3], target: [0, 0.5, 0] },
  objects: [{ shape: "plane", size: [4, 4] }, { shape: "sphere", transform: { translation: [0, 0.6, 0] } }],
  lights: [{ type: "directional", direction: [-0.4, -1, -0.3] }],
};
const umbra = new Client(URL);
const r = await umbra.render(SCENE);
check("render answers a PNG with an ETag", isPng(r.body) && r.etag && r.attempts === 1, [r.contentType, r.etag]);
const again = await umbra.render(SCENE, { etag: r.etag });
check("the same scene with its ETag is not modified (no body)", again.notModified && again.body === null, again.status);
try {
  await umbra.render({ ...SCENE, lights: [{ type: "directional", direction: [0, 0, 0] }] });
  check("a bad scene throws UmbraError", false);
} catch (e) {
  check("a bad scene throws UmbraError with the pointer", e instanceof UmbraError && e.status === 400 &&
        e.pointer === "/lights/0/direction" && e.detail.includes("zero"), String(e));
}
const w = await umbra.render(SCENE, { accept: "image/webp" });
check("Accept image/webp answers WebP", w.contentType === "image/webp" && Buffer.from(w.body.slice(0, 4)).toString() === "RIFF",
      w.contentType);
const d = mkdtempSync(path.join(tmpdir(), "umbra-node-"));
writeFileSync(path.join(d, "tri.obj"), "mtllib tri.mtl\nv -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nusemtl red\nf 1 2 3\n");
writeFileSync(path.join(d, "tri.mtl"), "newmtl red\nKd 1 0 0\n");
const m = await umbra.renderModel(path.join(d, "tri.obj"));
check("renderModel sends the .obj's .mtl (no warning)", isPng(m.body) && !m.warnings, m.warnings);
const bare = await umbra.renderModel(path.join(d, "tri.obj"), { files: [] });
check("without the .mtl the daemon names it", bare.warnings && bare.warnings.includes("tri.mtl"), bare.warnings);
rmSync(d, { recursive: true });

// ---- fake servers ----
let script = [], bodies = [];
const srv = http.createServer((req, res) => {
  const chunks = [];
  req.on("data", (c) => chunks.push(c));
  req.on("end", () => {
    bodies.push(Buffer.concat(chunks).toString());
    const [status, headers, body] = script[Math.min(bodies.length - 1, script.length - 1)];
    res.writeHead(status, headers);
    res.end(body);
  });
});
await new Promise((ok) => srv.listen(0, "127.0.0.1", ok));
const fakeUrl = `http://127.0.0.1:${srv.address().port}`;
const fake = new Client(fakeUrl, { retries: 5 });
script = [[503, { "Retry-After": "0" }, "{}"], [503, { "Retry-After": "0" }, "{}"],
          [200, { "Content-Type": "image/png", ETag: '"x"' }, Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x20])]];
const f = await fake.render(SCENE);
check("503 + Retry-After retried until 200", f.attempts === 3 && isPng(f.body), f.attempts);
check("every retry sends the same body", bodies.length === 3 && new Set(bodies).size === 1, bodies.length);
bodies = [];
script = [[400, { "Content-Type": "application/problem+json" }, '{"title":"Invalid scene","status":400,"detail":"bad","pointer":"/width"}']];
try {
  await fake.render(SCENE);
  check("a 400 throws", false);
} catch (e) {
  check("a 400 is not retried and throws with its pointer", bodies.length === 1 && e.pointer === "/width", String(e));
}
await new Promise((ok) => srv.close(ok));
try {
  await new Client(fakeUrl, { retries: 1 }).render(SCENE);
  check("a refused connection throws", false);
} catch (e) {
  check("a refused connection is retried, then throws (status 0)", e instanceof UmbraError && e.status === 0, String(e));
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
