#!/usr/bin/env python3
"""tests/http/gen_assets.py DIR — writes multi-file models for tests/http/assets.sh (standard
library only, deterministic):

  quad.gltf + quad.bin + halves.png   a 2x2 quad facing +Z, textured left half red, right half
                                      blue (glTF: v = 0 at the image's top)
  sub/quad.gltf                       the same quad in a subfolder, its files one level up
                                      ("../quad.bin", "../halves.png": inside the root)
  box.obj + box.mtl + halves.png      the same quad as an OBJ whose .mtl says map_Kd halves.png
  missing.gltf                        refers to nothing.bin, which does not exist
  escape.gltf                         refers to ../outside.bin (above the root)
  many.gltf + many.bin + t0..t19.png  one mesh with 20 primitives, each its own material and
                                      texture (20 distinct textures)
  notex.obj + notex.mtl               the OBJ quad whose .mtl names gone.png, which does not exist
  quadglb.stl                         the quad as a .glb (its .bin inside, halves.png beside it),
                                      misnamed .stl
"""
import json, os, struct, sys, zlib


def png(path, w, h, pixel):
    rows = b''.join(b'\0' + b''.join(bytes(pixel(x, y)) for x in range(w)) for y in range(h))
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff)
    data = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
    data += chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b'')
    open(path, 'wb').write(data)


POS = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
UV = [(0, 1), (1, 1), (1, 0), (0, 0)]
IDX = [0, 1, 2, 0, 2, 3]


def quad_bin():
    b = b''.join(struct.pack('<3f', *p) for p in POS) + b''.join(struct.pack('<2f', *t) for t in UV)
    b += struct.pack('<6H', *IDX)
    return b + b'\0' * (-len(b) % 4)


def gltf(buffer_uri, images, nprims=1):
    prims = [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": i} for i in range(nprims)]
    return {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": prims}],
        "buffers": [{"uri": buffer_uri, "byteLength": 92}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "images": [{"uri": u} for u in images],
        "textures": [{"source": i} for i in range(len(images))],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": i % len(images)}, "metallicFactor": 0,
                                                "roughnessFactor": 1}} for i in range(nprims)],
    }


def main():
    d = sys.argv[1]
    os.makedirs(os.path.join(d, 'sub'), exist_ok=True)
    open(os.path.join(d, 'quad.bin'), 'wb').write(quad_bin())
    png(os.path.join(d, 'halves.png'), 8, 8, lambda x, y: (255, 0, 0) if x < 4 else (0, 0, 255))
    json.dump(gltf('quad.bin', ['halves.png']), open(os.path.join(d, 'quad.gltf'), 'w'))
    json.dump(gltf('../quad.bin', ['../halves.png']), open(os.path.join(d, 'sub', 'quad.gltf'), 'w'))
    json.dump(gltf('nothing.bin', ['halves.png']), open(os.path.join(d, 'missing.gltf'), 'w'))
    json.dump(gltf('../outside.bin', ['halves.png']), open(os.path.join(d, 'escape.gltf'), 'w'))
    obj = 'mtllib box.mtl\n' + ''.join('v %g %g %g\n' % p for p in POS)
    obj += ''.join('vt %g %g\n' % (u, 1 - v) for u, v in UV)   # OBJ: v = 0 at the image's bottom
    obj += 'usemtl halves\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n'
    open(os.path.join(d, 'box.obj'), 'w').write(obj)
    open(os.path.join(d, 'box.mtl'), 'w').write('newmtl halves\nKd 1 1 1\nmap_Kd halves.png\n')
    names = ['t%d.png' % i for i in range(20)]
    for i, n in enumerate(names):
        png(os.path.join(d, n), 2, 2, lambda x, y, i=i: (10 * i, 255 - 10 * i, 128))
    open(os.path.join(d, 'many.bin'), 'wb').write(quad_bin())
    json.dump(gltf('many.bin', names, 20), open(os.path.join(d, 'many.gltf'), 'w'))
    open(os.path.join(d, 'notex.obj'), 'w').write(obj.replace('mtllib box.mtl', 'mtllib notex.mtl'))
    open(os.path.join(d, 'notex.mtl'), 'w').write('newmtl halves\nKd 1 1 1\nmap_Kd gone.png\n')
    doc = gltf(None, ['halves.png'])
    binary = quad_bin()
    doc['buffers'][0].pop('uri', None)
    js = json.dumps(doc).encode()
    js += b' ' * (-len(js) % 4)
    binary += b'\0' * (-len(binary) % 4)
    glb = struct.pack('<4sII', b'glTF', 2, 12 + 8 + len(js) + 8 + len(binary))
    glb += struct.pack('<I4s', len(js), b'JSON') + js + struct.pack('<I4s', len(binary), b'BIN\0') + binary
    open(os.path.join(d, 'quadglb.stl'), 'wb').write(glb)


if __name__ == '__main__':
    main()
