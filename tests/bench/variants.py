#!/usr/bin/env python3
"""Writes the benchmark's scene variants into DIR: thumb-512 with each shadow filter and with
pcf plus contact shadows, outdoor-csm with each directional mode, studio-spots with 1/4/16
shadowed lights, models of 10k/100k/1M triangles (binary STL, base64 inline, and by path:
model-*-path.json with the .stl files next to them, for build/tests/bench -a OUT_DIR), and a
16-frame turntable.
Usage: variants.py SHARED_BENCH_DIR OUT_DIR"""
import base64, copy, json, math, os, struct, sys

src, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
load = lambda n: json.load(open(os.path.join(src, n)))
def save(name, doc):
    with open(os.path.join(out, name), "w") as f:
        json.dump(doc, f)

thumb = load("thumb-512.json")
for f in ("hard", "pcf", "pcss", "vsm", "evsm"):
    d = copy.deepcopy(thumb)
    d["shadows"] = {"filter": f}
    if f == "pcss":
        d["lights"][0]["angular_diameter"] = 2.0
    save("thumb512-%s.json" % f, d)
# Contact shadows: the pcf variant with them on (one light: the difference is their cost per
# light, the view depth prepass included).
d = copy.deepcopy(thumb)
d["shadows"] = {"filter": "pcf", "contact": {"enabled": True}}
save("thumb512-pcf-contact.json", d)

# Outputs: encode cost per format and size.
for size in (256, 512, 1024):
    for fmt, extra in (("png8", {"format": "png"}), ("png16", {"format": "png", "bit_depth": 16}),
                       ("exr", {"format": "exr"}), ("exr-aovs", {"format": "exr", "aovs": ["shadow", "depth", "normal", "albedo"]})):
        d = copy.deepcopy(thumb)
        d["width"] = d["height"] = size
        d["output"] = extra
        save("out-%d-%s.json" % (size, fmt), d)

outdoor = load("outdoor-csm.json")
for m in ("fit", "cascades", "clipmap"):
    d = copy.deepcopy(outdoor)
    d["lights"][0].setdefault("shadow", {}).setdefault("directional", {})["mode"] = m
    save("outdoor-%s.json" % m, d)

studio = load("studio-spots.json")
shadowed = [i for i, l in enumerate(studio["lights"]) if l.get("shadow", True) is not False]
for n in (1, 4, 16):
    d = copy.deepcopy(studio)
    lights = [l for l in d["lights"] if l["type"] != "directional"]
    while len(lights) < n:
        l = copy.deepcopy(lights[len(lights) % max(1, len(lights))])
        if "position" in l:
            l["position"] = [l["position"][0] + 0.37 * len(lights), l["position"][1], l["position"][2] - 0.21 * len(lights)]
        lights.append(l)
    d["lights"] = lights[:n]
    save("studio-%dlights.json" % n, d)

def sphere_stl(tris):
    seg = max(8, int(math.sqrt(tris / 2)))
    rows, cols = seg, seg
    pts = lambda i, j: (math.sin(math.pi * i / rows) * math.cos(2 * math.pi * j / cols),
                        math.cos(math.pi * i / rows), math.sin(math.pi * i / rows) * math.sin(2 * math.pi * j / cols))
    body = bytearray()
    count = 0
    for i in range(rows):
        for j in range(cols):
            a, b, c, e = pts(i, j), pts(i, j + 1), pts(i + 1, j), pts(i + 1, j + 1)
            for t in ((a, b, c), (b, e, c)):
                body += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *p) for p in t) + b"\0\0"
                count += 1
    return b"\0" * 80 + struct.pack("<I", count) + bytes(body)

for n, label in ((10000, "10k"), (100000, "100k"), (1000000, "1m")):
    stl = sphere_stl(n)
    d = {"width": 512, "height": 512,
         "camera": {"fit": "objects", "direction": [-1, -0.6, -1], "margin": 0.1},
         "objects": [{"shape": "plane", "size": [20, 20], "transform": {"translation": [0, -1, 0]}},
                     {"shape": "model", "format": "stl", "data": base64.b64encode(stl).decode()}],
         "lights": [{"type": "directional", "direction": [-0.5, -1, -0.3]}]}
    save("model-%s.json" % label, d)
    # The same model by path (bench -a OUT_DIR): a cached import without a 70 MB JSON to parse.
    with open(os.path.join(out, "model-%s.stl" % label), "wb") as f:
        f.write(stl)
    d["objects"][1] = {"shape": "model", "path": "model-%s.stl" % label}
    save("model-%s-path.json" % label, d)

d = copy.deepcopy(studio)
d["turntable"] = {"frames": 16, "elevation": 25}
d.pop("camera", None)
d["width"], d["height"] = 256, 256
save("studio-turntable16.json", d)
d = copy.deepcopy(studio)
d["width"], d["height"] = 256, 256
save("studio-single256.json", d)

# A new model's thumbnail (issue 28): a bumpy closed sphere of ~100k triangles with a colour
# per vertex as a binary PLY (its smooth colours measure over the level's colour bound: drawn in full),
# and a 10k one, under the thumbnail preset at 256². build/tests/bench -s draws the sun map
# every run, as for a model never seen before.
def bumpy_ply(tris):
    nu = max(8, int(math.sqrt(tris)))
    nv = max(4, tris // (2 * nu) + 1)
    verts, faces = bytearray(), bytearray()
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu):
            ph = 2 * math.pi * i / nu
            x, y, z = math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)
            r = 1 + 0.08 * math.sin(7 * x + 3 * y) * math.cos(5 * z - 2 * y) + 0.03 * math.sin(23 * y + 11 * x)
            c = (int(127 + 120 * math.sin(3 * y)), int(127 + 120 * math.sin(4 * x + 1)), int(127 + 120 * math.cos(5 * z)))
            verts += struct.pack("<3f3B", r * x, r * y + 1.0, r * z, *c)
    count = 0
    for j in range(nv):
        for i in range(nu):
            a, b = j * nu + i, j * nu + (i + 1) % nu
            c, d = a + nu, b + nu
            if j > 0:
                faces += struct.pack("<B3I", 3, a, b, c); count += 1
            if j < nv - 1:
                faces += struct.pack("<B3I", 3, b, d, c); count += 1
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
            "element face %d\nproperty list uchar uint vertex_indices\nend_header\n" % ((nv + 1) * nu, count))
    return head.encode() + bytes(verts) + bytes(faces)

for n, label in ((10000, "10k"), (100000, "100k")):
    with open(os.path.join(out, "colour-%s.ply" % label), "wb") as f:
        f.write(bumpy_ply(n))
    save("thumb256-colour-%s.json" % label,
         {"preset": "thumbnail", "width": 256, "height": 256,
          "objects": [{"shape": "model", "path": "colour-%s.ply" % label}]})
