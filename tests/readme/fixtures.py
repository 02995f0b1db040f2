"""tests/readme/fixtures.py — the files the README's commands name, made in the scratch folder
(standard library only): models/ (generated meshes in OBJ and STL, and a .glb), chair.glb,
chair.ply, prints/ (a Z-up STL), gltf/ (a .gltf with its .bin), scene.json, chair.json (a
`path` model under models/) and jobs.jsonl. A command that names a file not made here fails:
add it here with the command."""
import json, os, struct, subprocess, sys

HERE = os.path.dirname(os.path.abspath(__file__))


def box(sx, sy, sz):
    """A box centred on the origin: 24 vertices (flat normals per face), 36 indices."""
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for sign in (-1, 1):
            n = [0, 0, 0]
            n[axis] = sign
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            base = len(pos)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis] = sign
                p[u], p[v] = a, b
                pos.append((p[0] * sx / 2, p[1] * sy / 2, p[2] * sz / 2))
                nrm.append(tuple(n))
            quad = (0, 1, 2, 0, 2, 3) if sign > 0 else (0, 2, 1, 0, 3, 2)
            idx += [base + q for q in quad]
    return pos, nrm, idx


def gltf_parts(pos, nrm, idx):
    """The glTF JSON (dict) and its binary buffer of one mesh."""
    bpos = b"".join(struct.pack("<3f", *p) for p in pos)
    bnrm = b"".join(struct.pack("<3f", *n) for n in nrm)
    bidx = b"".join(struct.pack("<H", i) for i in idx)
    bidx += b"\0" * (-len(bidx) % 4)
    bin_ = bpos + bnrm + bidx
    lo = [min(p[k] for p in pos) for k in range(3)]
    hi = [max(p[k] for p in pos) for k in range(3)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
        "buffers": [{"byteLength": len(bin_)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(bpos)},
                        {"buffer": 0, "byteOffset": len(bpos), "byteLength": len(bnrm)},
                        {"buffer": 0, "byteOffset": len(bpos) + len(bnrm), "byteLength": 2 * len(idx)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5123, "count": len(idx), "type": "SCALAR"}],
    }
    return doc, bin_


def glb(pos, nrm, idx):
    doc, bin_ = gltf_parts(pos, nrm, idx)
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_), 0x004E4942) + bin_
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def ply(pos, idx):
    lines = ["ply", "format ascii 1.0", "element vertex %d" % len(pos), "property float x", "property float y",
             "property float z", "element face %d" % (len(idx) // 3), "property list uchar int vertex_indices",
             "end_header"]
    lines += ["%g %g %g" % p for p in pos]
    lines += ["3 %d %d %d" % tuple(idx[i:i + 3]) for i in range(0, len(idx), 3)]
    return ("\n".join(lines) + "\n").encode()


def stl(pos, idx):
    out = b"\0" * 80 + struct.pack("<I", len(idx) // 3)
    for i in range(0, len(idx), 3):
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *pos[j]) for j in idx[i:i + 3]) + b"\0\0"
    return out


def put(path, data):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


SCENE = {"width": 128, "height": 128, "camera": {"position": [3, 2.5, 4], "target": [0, 0.4, 0]},
         "objects": [{"shape": "plane", "size": [6, 6]}, {"shape": "box", "transform": {"translation": [-0.6, 0.5, 0]}},
                     {"shape": "sphere", "radius": 0.5, "transform": {"translation": [0.8, 0.5, 0]}}],
         "lights": [{"type": "directional", "direction": [-1, -2, -1], "angular_diameter": 2}]}


def make(root):
    """Writes every fixture under root."""
    subprocess.run([sys.executable, os.path.join(HERE, "..", "cli", "gen_models.py"), os.path.join(root, "models"), "8"],
                   check=True, stdout=subprocess.DEVNULL)
    chair = box(1.0, 1.6, 0.8)
    put(os.path.join(root, "models", "chair.glb"), glb(*chair))
    put(os.path.join(root, "chair.glb"), glb(*chair))
    put(os.path.join(root, "chair.ply"), ply(chair[0], chair[2]))
    tall = box(0.4, 0.4, 2.0)   # a post along Z: a Z-up file lying on its side in Y-up
    put(os.path.join(root, "prints", "post.stl"), stl(tall[0], tall[2]))
    doc, bin_ = gltf_parts(*chair)
    doc["buffers"][0]["uri"] = "chair.bin"
    put(os.path.join(root, "gltf", "chair.gltf"), json.dumps(doc))
    put(os.path.join(root, "gltf", "chair.bin"), bin_)
    put(os.path.join(root, "scene.json"), json.dumps(SCENE))
    by_path = dict(SCENE, objects=[{"shape": "plane", "size": [6, 6]}, {"shape": "model", "path": "chair.glb"}])
    put(os.path.join(root, "chair.json"), json.dumps(by_path))
    jobs = [{"scene": "scene.json", "output": "a.png"},
            {"scene": dict(SCENE, output={"format": "webp", "quality": 80}), "output": "b.webp"}]
    put(os.path.join(root, "jobs.jsonl"), "".join(json.dumps(j) + "\n" for j in jobs))
