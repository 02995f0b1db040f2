#!/usr/bin/env python3
"""tests/fuzz/make_seeds.py — writes the seed corpora of the model-import fuzz targets into
tests/fuzz/corpus/<target>/: small models built here (no fetched files). Run from the repository
root; the files it writes are committed."""
import base64, json, os, struct

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")

def put(target, name, data):
    d = os.path.join(ROOT, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

QUAD_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
QUAD_F = [(0, 1, 2), (0, 2, 3)]

# obj
put("fuzz_model_obj", "tri.obj", "v -1 0 -1\nv 1 0 -1\nv 0 1.5 0\nf 1 2 3\n")
put("fuzz_model_obj", "quad-uv-normals.obj",
    "o quad\n" + "".join("v %g %g %g\n" % v for v in QUAD_V) + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
    "usemtl none\ns 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
# obj for the own reader (api/obj_import.c): negative indices, quads, objects and groups,
# materials (the .mtl is not sent: Assimp's named empty materials), a pentagon (left to Assimp)
GRID = "".join("v %d %g %d\nvt %g %g\nvn 0 1 %g\n" % (i, 0.1 * ((i * j) % 3), j, i / 2, j / 2, 0.1 * i)
               for j in range(3) for i in range(3))
put("fuzz_model_obj", "grid-groups-materials.obj",
    "mtllib grid.mtl\n" + GRID + "o sheet\nusemtl red\nf -9/-9/-9 -6/-6/-6 -5/-5/-5 -8/-8/-8\ng row 2\n"
    "f 2/2/2 5/5/5 6/6/6\nusemtl wood\nf 2//2 6//6 3//3\ng\nf 4/4 7/7 8/8 5/5\nf 5 8 9 6\n")
put("fuzz_model_obj", "pentagon.obj", "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.5 0\nv -0.5 1 0\nf 1 2 3 4 5\n")
# stl
put("fuzz_model_stl", "tetra-ascii.stl",
    "solid t\n" + "".join("facet normal 0 0 0\nouter loop\n" + "".join("vertex %g %g %g\n" % p for p in tri) +
                          "endloop\nendfacet\n" for tri in [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
                                                             ((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, 0, 1), (0, 1, 0))]) + "endsolid t\n")
stl = bytearray(80) + struct.pack("<I", 2)
for f in QUAD_F:
    stl += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *QUAD_V[i]) for i in f) + b"\0\0"
put("fuzz_model_stl", "quad-binary.stl", bytes(stl))
# ply
hdr = ("ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 2\nproperty list uchar int vertex_indices\nend_header\n")
put("fuzz_model_ply", "quad-ascii.ply", hdr % "ascii" + "".join("%g %g %g\n" % v for v in QUAD_V) +
    "".join("3 %d %d %d\n" % f for f in QUAD_F))
put("fuzz_model_ply", "quad-binary.ply", (hdr % "binary_little_endian").encode() +
    b"".join(struct.pack("<3f", *v) for v in QUAD_V) + b"".join(struct.pack("<B3i", 3, *f) for f in QUAD_F))
# ply for the own reader (api/ply_import.c): big-endian with normals, uvs and ushort colours;
# face colours; a quad
qhdr = ("ply\nformat %s 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
        "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
        "property ushort red\nproperty ushort green\nproperty ushort blue\n"
        "element face 1\nproperty list uchar uint vertex_indices\nend_header\n")
put("fuzz_model_ply", "quad-be-attributes.ply", (qhdr % "binary_big_endian").encode() +
    b"".join(struct.pack(">3d3f2f3H", *v, 0, 0, 1, v[0], v[1], 60000, 3000, 100) for v in QUAD_V) +
    struct.pack(">B4I", 4, 0, 1, 2, 3))
fhdr = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 2\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nend_header\n")
put("fuzz_model_ply", "face-colours.ply", fhdr + "".join("%g %g %g\n" % v for v in QUAD_V) +
    "3 0 1 2 255 0 0\n3 0 2 3 0 0 255\n")
# gltf / glb: one triangle, positions + indices in one buffer
pos = b"".join(struct.pack("<3f", *v) for v in [(0, 0, 0), (1, 0, 0), (0, 1, 0)])
idx = struct.pack("<3H", 0, 1, 2) + b"\0\0"
buf = pos + idx
def gltf(uri):
    b = {"byteLength": len(buf)}
    if uri: b["uri"] = uri
    return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "translation": [0, 0.5, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.25, 1], "metallicFactor": 0}}],
            "buffers": [b],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                          {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]}
put("fuzz_model_gltf", "tri.gltf", json.dumps(gltf("data:application/octet-stream;base64," + base64.b64encode(buf).decode())))
j = json.dumps(gltf(None)).encode()
j += b" " * (-len(j) % 4)
glb = b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + 8 + len(buf)) + struct.pack("<I", len(j)) + b"JSON" + j + \
      struct.pack("<I", len(buf)) + b"BIN\0" + buf
put("fuzz_model_glb", "tri.glb", glb)
# EXT_mesh_gpu_instancing (api/gltf_instancing.c): the triangle at three instances, TRANSLATION
# floats in the BIN chunk, ROTATION normalized shorts in a data: URI buffer
ibuf = buf + struct.pack("<9f", 0, 0, 0, 2, 0, 0, 0, 2, 0)
rot = struct.pack("<12h", 0, 0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 32767)
g = gltf(None)
g["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
g["buffers"] = [{"byteLength": len(ibuf)}, {"byteLength": len(rot), "uri": "data:application/octet-stream;base64," +
                                           base64.b64encode(rot).decode()}]
g["bufferViews"] += [{"buffer": 0, "byteOffset": 44, "byteLength": 36}, {"buffer": 1, "byteOffset": 0, "byteLength": 24}]
g["accessors"] += [{"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3"},
                   {"bufferView": 3, "componentType": 5122, "normalized": True, "count": 3, "type": "VEC4"}]
g["nodes"][0]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 2, "ROTATION": 3}}}
j = json.dumps(g).encode()
j += b" " * (-len(j) % 4)
put("fuzz_model_glb", "instanced.glb", b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + 8 + len(ibuf)) +
    struct.pack("<I", len(j)) + b"JSON" + j + struct.pack("<I", len(ibuf)) + b"BIN\0" + ibuf)
# KHR_mesh_quantization (api/gltf_decode.c): positions as shorts under a node scale, normals
# as normalized bytes
qbuf = b"".join(struct.pack("<4h", x, y, 0, 0) for x, y in [(0, 0), (1000, 0), (1000, 1000), (0, 1000)]) + \
       b"".join(struct.pack("<4b", 0, 0, 127, 0) for _ in range(4)) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)
q = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"],
     "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "scale": [0.001, 0.001, 0.001]}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2}]}],
     "buffers": [{"byteLength": len(qbuf)}],
     "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8},
                     {"buffer": 0, "byteOffset": 32, "byteLength": 16, "byteStride": 4},
                     {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
     "accessors": [{"bufferView": 0, "componentType": 5122, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1000, 1000, 0]},
                   {"bufferView": 1, "componentType": 5120, "normalized": True, "count": 4, "type": "VEC3"},
                   {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]}
j = json.dumps(q).encode()
j += b" " * (-len(j) % 4)
qbuf += b"\0" * (-len(qbuf) % 4)
put("fuzz_model_glb", "quantized.glb", b"glTF" + struct.pack("<II", 2, 12 + 8 + len(j) + 8 + len(qbuf)) +
    struct.pack("<I", len(j)) + b"JSON" + j + struct.pack("<I", len(qbuf)) + b"BIN\0" + qbuf)
# draco.glb (KHR_draco_mesh_compression, a quad) is not written here: Python has no Draco
# encoder. It is tests/util/models.c's test_draco_glb() of the quad (0,0,0)..(1,1,0) with
# normals +z and uvs, edgebreaker, 11-bit positions, UNSIGNED_SHORT indices, written by a
# three-line C main linked with tests/util/models.o and draco_encode.o; committed as is.
# replies of the importer (api/model_wire.h)
# the wire version as api/model_wire.h has it now (seeds of an older version are all refused at
# the header, and the fuzzer never reaches the decoder: the version-7 seeds did that at 8 and 9)
import re
WIRE_VERSION = int(re.search(r"#define API_WIRE_VERSION (\d+)u",
                             open(os.path.join(os.path.dirname(ROOT), "..", "..", "api", "model_wire.h")).read()).group(1))
def header(kind, status, msg=b""):
    return b"UMBRAIMP" + struct.pack("<IIII", WIRE_VERSION, kind, status, len(msg)) + msg
tex = struct.pack("<II", 2, 1) + bytes([255, 0, 0, 255, 0, 255, 0, 255])
# material: 13 floats (the last the see-through share, 0.5 here), alpha mode, a texture per
# slot (base, metal-rough, normal, occlusion, emissive, clearcoat, its roughness and normal,
# sheen colour and roughness, specular and its colour, transmission), per slot the sampling
# (packed modes + a 2x3 uv transform; bit 9: the second uv set, here on the occlusion slot),
# then the PBR extensions (bits: clearcoat, sheen and 1 << 16, the specular-glossiness model; 11
# floats and the ior)
mat = struct.pack("<13f", 1, 1, 1, 1, 0.5, 0, 1, 1, 1, 0.5, 1, 1, 0.5) + \
      struct.pack("<I13i", 2, 0, -1, 0, -1, 0, 0, -1, -1, 0, -1, -1, -1, 0) + \
      b"".join(struct.pack("<I6f", 0x45 | (0x200 if s == 3 else 0), 1, 0, 0.5, 0, 1, 0) for s in range(13)) + \
      struct.pack("<I12f", 3 | 1 << 16, 1, 0.1, 1, 0.5, 0.5, 0.5, 0.8, 1, 1, 1, 1, 1.5)
# mesh: normals, uvs, colours, tangents, single-sided, a second uv set (flag 128, after the uvs)
mesh = struct.pack("<4I", 3, 3, 0, 31 | 128) + pos + struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1) + \
       struct.pack("<6f", 0, 0, 1, 0, 0, 1) + struct.pack("<6f", 0.5, 0.5, 1, 0.5, 0.5, 1) + \
       bytes([255, 0, 0, 255] * 3) + struct.pack("<12f", 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, -1) + struct.pack("<3I", 0, 1, 2)
inst = struct.pack("<I", 0) + struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1)
warn = b"skins are not applied (drawn in the bind pose)"
# the importer's stage times f32[4], texture_side texture_max, then the counts
times = struct.pack("<4f", 1, 2, 0, 0) + struct.pack("<II", 0, 2)
# the warnings padded with zeros to a multiple of 4 bytes
put("fuzz_import_reply", "model.bin", header(1, 0) + times + struct.pack("<5I", 1, 1, 1, 1, len(warn)) + warn +
    b"\0" * (-len(warn) % 4) + tex + mat + mesh + inst)
# the same mesh with its indices 0..n-1 left out (flag 512: the daemon fills them in)
put("fuzz_import_reply", "model-identity.bin", header(1, 0) + times + struct.pack("<5I", 1, 1, 1, 1, len(warn)) + warn +
    b"\0" * (-len(warn) % 4) + tex + mat + mesh[:4 * 3] + struct.pack("<I", 31 | 128 | 512) + mesh[16:-12] + inst)
put("fuzz_import_reply", "image.bin", header(2, 0) + tex)
put("fuzz_import_reply", "error.bin", header(1, 1, b"PLY: bad header"))
