#!/usr/bin/env python3
"""tests/bench/farm_corpus.py DIR — writes the corpus of the farm benchmark on new models
(tests/bench/farm_bench.py) into DIR: 32 distinct models of about 10k, 100k and 1M triangles as
OBJ, binary STL, binary little-endian PLY and glb, six of the glb with an embedded 1024² or 2048²
PNG or JPEG base colour texture, and DIR/manifest.json (per file: format, class, triangles,
vertices, shape, texture, bytes).

Every model is its own surface from a seeded RNG: bumpy blobs (closed), wavy tori (closed),
torus-knot tubes (closed), vases (a surface of revolution closed at the foot, open at the rim)
and displaced terrain tiles (open), all Y up, triangles wound counter-clockwise seen from outside.
Deterministic: the same bytes on every run (no timestamps). Standard library only; the JPEG
textures go through cjpeg (Debian's libjpeg-turbo-progs, a test tool of deploy/install-deps.sh),
or Pillow when it is installed. About 30-40 s on the 2-core machine."""
import json, math, os, random, shutil, struct, subprocess, sys, zlib
from array import array

# ---- surfaces: a (nu+1) x (nv+1) grid of f(u, v), u around, v along --------------------------


class Surface:
    """A parametric grid. pos: flat float list (x, y, z per vertex, row j = v index); the seam
    column u = 1 repeats u = 0 (its own uvs), a pole row collapses to one point and gets one
    triangle per quad. flip: winding reversed so that faces point outward (see orient())."""

    def __init__(self, nu, nv, f, pole0=False, pole1=False, open_surface=False, wrap_v=False):
        self.nu, self.nv, self.pole0, self.pole1, self.open = nu, nv, pole0, pole1, open_surface
        self.wrap_v = wrap_v
        pos = []
        ext = pos.extend
        for j in range(nv + 1):
            v = j / nv
            for i in range(nu + 1):
                ext(f(i / nu, v))
        self.pos = pos
        self.flip = False

    def vertices(self):
        return (self.nu + 1) * (self.nv + 1)

    def triangles(self):
        return 2 * self.nu * self.nv - self.nu * (self.pole0 + self.pole1)

    def tri_indices(self):
        """Yields (a, b, c) vertex indices, wound outward."""
        nu, nv, w = self.nu, self.nv, self.nu + 1
        for j in range(nv):
            r0, r1 = j * w, (j + 1) * w
            for i in range(nu):
                a, b, c, d = r0 + i, r0 + i + 1, r1 + i, r1 + i + 1
                if self.flip:
                    if not (j == 0 and self.pole0):
                        yield a, b, c
                    if not (j == nv - 1 and self.pole1):
                        yield b, d, c
                else:
                    if not (j == 0 and self.pole0):
                        yield a, c, b
                    if not (j == nv - 1 and self.pole1):
                        yield b, c, d

    def index_array(self):
        idx = array("I")
        for t in self.tri_indices():
            idx.extend(t)
        return idx

    def normals(self):
        """Per-vertex normals from central differences on the grid (wrapping around u, one-sided
        at open edges, wrapping around v on tubes), the pole rows from the fan around them; unit
        length, outward."""
        nu, nv, w, p = self.nu, self.nv, self.nu + 1, self.pos
        out = [0.0] * len(p)
        sign = -1.0 if self.flip else 1.0
        for j in range(nv + 1):
            jm, jp = max(j - 1, 0) * w, min(j + 1, nv) * w
            if self.wrap_v and j in (0, nv):
                jm, jp = (nv - 1) * w, w
            row = j * w
            for i in range(nu + 1):
                im = i - 1 if i > 0 else nu - 1
                ip = i + 1 if i < nu else 1
                a, b = 3 * (row + ip), 3 * (row + im)
                ux, uy, uz = p[a] - p[b], p[a + 1] - p[b + 1], p[a + 2] - p[b + 2]
                a, b = 3 * (jp + i), 3 * (jm + i)
                vx, vy, vz = p[a] - p[b], p[a + 1] - p[b + 1], p[a + 2] - p[b + 2]
                # triangle (a, c, b) has normal (c - a) x (b - a) = dv x du
                nx, ny, nz = vy * uz - vz * uy, vz * ux - vx * uz, vx * uy - vy * ux
                l = math.sqrt(nx * nx + ny * ny + nz * nz)
                k = 3 * (row + i)
                if l > 1e-20:
                    out[k], out[k + 1], out[k + 2] = sign * nx / l, sign * ny / l, sign * nz / l
        for j, on in ((0, self.pole0), (nv, self.pole1)):
            if not on:
                continue
            ring = (1 if j == 0 else nv - 1) * w
            sx = sy = sz = 0.0
            for i in range(nu):
                k = 3 * (ring + i)
                sx, sy, sz = sx + out[k], sy + out[k + 1], sz + out[k + 2]
            l = math.sqrt(sx * sx + sy * sy + sz * sz) or 1.0
            for i in range(nu + 1):
                k = 3 * (j * w + i)
                out[k], out[k + 1], out[k + 2] = sx / l, sy / l, sz / l
        return out


def orient(make, centre):
    """Builds a 24 x 12 copy of the surface and sums (face normal . (centroid - centre)): a
    negative sum means the faces point inward, so the full surface gets flip = True."""
    s = make(24, 12)
    p, acc = s.pos, 0.0
    for a, b, c in s.tri_indices():
        ax, ay, az = p[3 * a:3 * a + 3]
        bx, by, bz = p[3 * b:3 * b + 3]
        cx, cy, cz = p[3 * c:3 * c + 3]
        ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
        n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
        m = ((ax + bx + cx) / 3 - centre[0], (ay + by + cy) / 3 - centre[1], (az + bz + cz) / 3 - centre[2])
        acc += n[0] * m[0] + n[1] * m[1] + n[2] * m[2]
    return acc < 0


def waves(rnd, n, amp, fmin, fmax):
    """n plane waves on the unit sphere: (direction, frequency, phase, amplitude)."""
    out = []
    for _ in range(n):
        z, t = rnd.uniform(-1, 1), rnd.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        out.append((r * math.cos(t), z, r * math.sin(t), rnd.uniform(fmin, fmax), rnd.uniform(0, 6.3),
                    amp * rnd.uniform(0.4, 1.0)))
    return out


def blob(rnd):
    """A lumpy closed rock: a sphere whose radius is 1 + a sum of waves over the direction, stretched."""
    w = waves(rnd, rnd.randint(4, 7), rnd.uniform(0.06, 0.14), 2.0, 7.0)
    st = (rnd.uniform(0.8, 1.3), rnd.uniform(0.6, 1.1), rnd.uniform(0.8, 1.3))
    sin, cos, pi = math.sin, math.cos, math.pi

    def f(u, v):
        th, ph = pi * v, 2 * pi * u
        s = sin(th)
        x, y, z = s * cos(ph), cos(th), s * sin(ph)
        r = 1.0
        for a, b, c, fr, phase, amp in w:
            r += amp * sin(fr * (a * x + b * y + c * z) + phase)
        return r * x * st[0], r * y * st[1], r * z * st[2]

    def make(nu, nv):
        return Surface(nu, nv, f, pole0=True, pole1=True)
    return make, (0.0, 0.0, 0.0), 2.0  # aspect nu / nv


def torus(rnd):
    """A closed torus lying flat, its tube radius rippling around both circles."""
    R, r0 = 1.0, rnd.uniform(0.25, 0.45)
    k1, k2, amp = rnd.randint(3, 9), rnd.randint(2, 6), rnd.uniform(0.08, 0.2)
    tilt = rnd.uniform(-0.35, 0.35)
    sin, cos, tau = math.sin, math.cos, 2 * math.pi

    def f(u, v):
        a, b = tau * u, tau * v
        r = r0 * (1 + amp * sin(k1 * a) * cos(k2 * b + a))
        x, y, z = (R + r * cos(b)) * cos(a), r * sin(b), (R + r * cos(b)) * sin(a)
        return x, y * cos(tilt) - z * sin(tilt), y * sin(tilt) + z * cos(tilt)

    def make(nu, nv):
        return Surface(nu, nv, f, wrap_v=True)
    return make, None, 2.5


def knot(rnd):
    """A closed tube along a (p, q) torus knot."""
    p, q = rnd.choice([(2, 3), (3, 2), (2, 5), (3, 4), (3, 5)])
    R, rr, tube = 1.0, rnd.uniform(0.35, 0.5), rnd.uniform(0.12, 0.18)
    sin, cos, tau = math.sin, math.cos, 2 * math.pi

    def centre(t):
        a = tau * t
        rad = R + rr * cos(q * a)
        return rad * cos(p * a), rr * sin(q * a), rad * sin(p * a)

    def f(u, v):
        c0, c1 = centre(u - 1e-4), centre(u + 1e-4)
        c = centre(u)
        tx, ty, tz = c1[0] - c0[0], c1[1] - c0[1], c1[2] - c0[2]
        l = math.sqrt(tx * tx + ty * ty + tz * tz)
        tx, ty, tz = tx / l, ty / l, tz / l
        # a frame from the tangent and the radial direction (never parallel on these knots)
        rx, rz = c[0], c[2]
        l = math.sqrt(rx * rx + rz * rz)
        rx, ry, rz = rx / l, 0.0, rz / l
        d = rx * tx + rz * tz
        nx, ny, nz = rx - d * tx, ry - d * ty, rz - d * tz
        l = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / l, ny / l, nz / l
        bx, by, bz = ty * nz - tz * ny, tz * nx - tx * nz, tx * ny - ty * nx
        b = tau * v
        cb, sb = cos(b) * tube, sin(b) * tube
        return c[0] + cb * nx + sb * bx, c[1] + cb * ny + sb * by, c[2] + cb * nz + sb * bz

    def make(nu, nv):
        return Surface(nu, nv, f, wrap_v=True)
    return make, None, 10.0


def vase(rnd):
    """A surface of revolution with fluted sides: closed at its foot (a pole), open at the rim."""
    bulge, neck, flare = rnd.uniform(0.5, 0.9), rnd.uniform(0.2, 0.4), rnd.uniform(0.35, 0.6)
    flutes, depth, h = rnd.randint(6, 16), rnd.uniform(0.02, 0.06), rnd.uniform(1.6, 2.4)
    sin, cos, pi, tau = math.sin, math.cos, math.pi, 2 * math.pi

    def profile(t):
        if t < 0.08:  # the foot: a disc closing at the axis
            return 0.5 * bulge * math.sqrt(t / 0.08), 0.0
        s = (t - 0.08) / 0.92
        body = bulge * sin(pi * min(s / 0.75, 1.0)) ** 0.8
        top = neck + (flare - neck) * max(0.0, (s - 0.75) / 0.25) ** 2
        return max(body, top) if s > 0.5 else max(body, 0.5 * bulge), s * h

    def f(u, v):
        r, y = profile(v)
        a = tau * u
        r *= 1 + depth * sin(flutes * a) * min(1.0, 10 * v)
        return r * cos(a), y - h / 2, r * sin(a)

    def make(nu, nv):
        return Surface(nu, nv, f, pole0=True, open_surface=True)
    return make, (0.0, 0.0, 0.0), 1.5


def terrain(rnd):
    """An open square tile of hills: a height field over x, z (no seam: u does not wrap)."""
    hills = [(rnd.uniform(-0.8, 0.8), rnd.uniform(-0.8, 0.8), rnd.uniform(0.15, 0.4), rnd.uniform(-0.25, 0.45))
             for _ in range(rnd.randint(4, 8))]
    ridges = waves(rnd, 3, 0.04, 6.0, 14.0)
    exp, sin = math.exp, math.sin

    def f(u, v):
        x, z = 2 * u - 1, 2 * v - 1
        y = 0.0
        for hx, hz, s, a in hills:
            dx, dz = x - hx, z - hz
            y += a * exp(-(dx * dx + dz * dz) / (s * s))
        for a, b, c, fr, phase, amp in ridges:
            y += amp * sin(fr * (a * x + c * z) + phase)
        return x, y, z

    def make(nu, nv):
        return Surface(nu, nv, f, open_surface=True)
    return make, (0.0, -10.0, 0.0), 1.0


SHAPES = {"blob": blob, "torus": torus, "knot": knot, "vase": vase, "terrain": terrain}


def build(shape, seed, target):
    """The surface of `shape` from `seed` with about `target` triangles."""
    rnd = random.Random(seed)
    make, centre, aspect = SHAPES[shape](rnd)
    poles = {"blob": 2, "vase": 1}.get(shape, 0)
    # 2 nu nv - poles nu = target, nu = aspect nv
    nv = max(4, round(math.sqrt(target / (2 * aspect))))
    nu = max(8, round((target / (2 * nv - poles))))
    s = make(nu, nv)
    if centre is None:  # tori and knots: outward is away from the tube's axis; test one sample
        s.flip = orient_tube(make)
    else:
        s.flip = orient(make, centre)
    return s


def orient_tube(make):
    """Tori and knots have no single inside point: compare each face normal with the direction
    from the grid row's centre (the tube's axis point at that u) on a low-resolution copy."""
    s = make(24, 12)
    w, p, acc = s.nu + 1, s.pos, 0.0
    for a, b, c in s.tri_indices():
        i = a % w
        cx = sum(p[3 * (j * w + i)] for j in range(s.nv)) / s.nv
        cy = sum(p[3 * (j * w + i) + 1] for j in range(s.nv)) / s.nv
        cz = sum(p[3 * (j * w + i) + 2] for j in range(s.nv)) / s.nv
        ax, ay, az = p[3 * a:3 * a + 3]
        bx, by, bz = p[3 * b:3 * b + 3]
        qx, qy, qz = p[3 * c:3 * c + 3]
        ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, qx - ax, qy - ay, qz - az
        n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
        acc += n[0] * (ax - cx) + n[1] * (ay - cy) + n[2] * (az - cz)
    return acc < 0


# ---- writers ---------------------------------------------------------------------------------


def write_stl(path, s, name):
    p = s.pos
    tri = struct.Struct("<12fH").pack
    sqrt = math.sqrt
    out = []
    app = out.append
    for a, b, c in s.tri_indices():
        a, b, c = 3 * a, 3 * b, 3 * c
        ax, ay, az, bx, by, bz, cx, cy, cz = p[a], p[a + 1], p[a + 2], p[b], p[b + 1], p[b + 2], p[c], p[c + 1], p[c + 2]
        ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        l = sqrt(nx * nx + ny * ny + nz * nz) or 1.0
        app(tri(nx / l, ny / l, nz / l, ax, ay, az, bx, by, bz, cx, cy, cz, 0))
    head = ("umbra farm corpus " + name).encode()[:80].ljust(80, b" ")
    with open(path, "wb") as fh:
        fh.write(head + struct.pack("<I", len(out)))
        fh.write(b"".join(out))
    return len(out)


def write_obj(path, s, name, uvs):
    p, lines = s.pos, ["# umbra farm corpus " + name, "o " + name]
    lines += ["v %.5f %.5f %.5f" % (p[k], p[k + 1], p[k + 2]) for k in range(0, len(p), 3)]
    if uvs:
        w, h = s.nu + 1, s.nv + 1
        lines += ["vt %.5f %.5f" % (i / s.nu, j / s.nv) for j in range(h) for i in range(w)]
        lines += ["f %d/%d %d/%d %d/%d" % (a + 1, a + 1, b + 1, b + 1, c + 1, c + 1) for a, b, c in s.tri_indices()]
    else:
        lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in s.tri_indices()]
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return s.triangles()


def write_ply(path, s, name, colours):
    """Binary little-endian PLY; with colours, a uchar RGB per vertex (a band pattern by height)."""
    p, nvert = s.pos, s.vertices()
    head = ["ply", "format binary_little_endian 1.0", "comment umbra farm corpus " + name,
            "element vertex %d" % nvert, "property float x", "property float y", "property float z"]
    if colours:
        head += ["property uchar red", "property uchar green", "property uchar blue"]
    ntri = s.triangles()
    head += ["element face %d" % ntri, "property list uchar int vertex_indices", "end_header"]
    with open(path, "wb") as fh:
        fh.write(("\n".join(head) + "\n").encode())
        if colours:
            ys = p[1::3]
            lo, hi = min(ys), max(ys)
            rec = struct.Struct("<3f3B").pack
            pal = colours
            body = []
            for k in range(nvert):
                y = p[3 * k + 1]
                c = pal[min(len(pal) - 1, int((y - lo) / (hi - lo + 1e-9) * len(pal)))]
                body.append(rec(p[3 * k], y, p[3 * k + 2], *c))
            fh.write(b"".join(body))
        else:
            fh.write(array("f", p).tobytes())
        face = struct.Struct("<B3i").pack
        fh.write(b"".join(face(3, a, b, c) for a, b, c in s.tri_indices()))
    return ntri


def write_glb(path, s, name, colour, image, mime, uv_repeat):
    """glb with POSITION, NORMAL (and TEXCOORD_0 with a texture), uint32 indices, one material:
    base colour factor, or an embedded base colour image; open surfaces are double-sided."""
    pos = array("f", s.pos)
    nrm = array("f", s.normals())
    idx = s.index_array()
    chunks, views, acc = [], [], []

    def view(data, target=None):
        off = sum(len(c) for c in chunks)
        chunks.append(data + b"\0" * (-len(data) % 4))
        v = {"buffer": 0, "byteOffset": off, "byteLength": len(data)}
        if target:
            v["target"] = target
        views.append(v)
        return len(views) - 1

    xs, ys, zs = s.pos[0::3], s.pos[1::3], s.pos[2::3]
    acc.append({"bufferView": view(pos.tobytes(), 34962), "componentType": 5126, "count": s.vertices(),
                "type": "VEC3", "min": [min(xs), min(ys), min(zs)], "max": [max(xs), max(ys), max(zs)]})
    acc.append({"bufferView": view(nrm.tobytes(), 34962), "componentType": 5126, "count": s.vertices(),
                "type": "VEC3"})
    attrs = {"POSITION": 0, "NORMAL": 1}
    mat = {"name": name, "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.6}}
    if s.open:
        mat["doubleSided"] = True
    doc = {"asset": {"version": "2.0", "generator": "umbra tests/bench/farm_corpus.py"}}
    if image is not None:
        ru, rv = uv_repeat
        uv = array("f")
        for j in range(s.nv + 1):
            for i in range(s.nu + 1):
                uv.append(ru * i / s.nu)
                uv.append(rv * j / s.nv)
        acc.append({"bufferView": view(uv.tobytes(), 34962), "componentType": 5126, "count": s.vertices(),
                    "type": "VEC2"})
        attrs["TEXCOORD_0"] = len(acc) - 1
        doc["images"] = [{"bufferView": view(image), "mimeType": mime}]
        doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]
        doc["textures"] = [{"sampler": 0, "source": 0}]
        mat["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    else:
        mat["pbrMetallicRoughness"]["baseColorFactor"] = list(colour) + [1.0]
    acc.append({"bufferView": view(idx.tobytes(), 34963), "componentType": 5125, "count": len(idx),
                "type": "SCALAR"})
    doc.update({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": [{"attributes": attrs, "indices": len(acc) - 1, "material": 0}]}],
        "materials": [mat], "accessors": acc, "bufferViews": views,
        "buffers": [{"byteLength": sum(len(c) for c in chunks)}],
    })
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary = b"".join(chunks)
    with open(path, "wb") as fh:
        fh.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(binary)))
        fh.write(struct.pack("<I4s", len(js), b"JSON") + js)
        fh.write(struct.pack("<I4s", len(binary), b"BIN\0") + binary)
    return len(idx) // 3


# ---- textures: RGB rows from tiles, bands and noise, with big-integer XOR for speed -------------


def texture_rows(size, seed):
    """Yields `size` RGB rows of `size` pixels: a board of tiles in a random palette, bands of
    another, and low-bit noise (so neither PNG nor JPEG compresses it to nothing)."""
    rnd = random.Random(seed)
    pal = [bytes(rnd.randrange(40, 256) for _ in range(3)) for _ in range(rnd.randint(3, 6))]
    tiles = rnd.choice([8, 16, 32])
    tw = size // tiles
    band_rows = []
    for by in range(tiles):
        row = b"".join(pal[(bx * 7 + by * 3 + (bx ^ by)) % len(pal)] * tw for bx in range(tiles))
        band_rows.append(int.from_bytes(row, "little"))
    mask = int.from_bytes(b"\x1f" * (3 * size), "little")
    noise = [int.from_bytes(rnd.randbytes(3 * size), "little") & mask for _ in range(61)]
    stripe = int.from_bytes(b"\x60" * (3 * size), "little")
    for y in range(size):
        v = band_rows[y // tw] ^ noise[(y * 17) % 61]
        if (y // max(1, tw // 4)) % 4 == 0:  # a thin darker stripe in every tile row
            v &= ~stripe
        yield v.to_bytes(3 * size, "little")


def png_bytes(size, seed):
    z = zlib.compressobj(6)
    parts = [z.compress(b"\0" + row) for row in texture_rows(size, seed)]
    data = b"".join(parts) + z.flush()

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", data) + chunk(b"IEND", b""))


def jpeg_bytes(size, seed):
    raw = b"".join(texture_rows(size, seed))
    try:
        from PIL import Image  # python3-pil, when present
        import io
        buf = io.BytesIO()
        Image.frombytes("RGB", (size, size), raw).save(buf, "JPEG", quality=90)
        return buf.getvalue()
    except ImportError:
        pass
    if not shutil.which("cjpeg"):
        sys.exit("farm_corpus.py: JPEG textures need cjpeg (apt-get install libjpeg-turbo-progs, "
                 "see deploy/install-deps.sh) or python3-pil")
    ppm = b"P6 %d %d 255\n" % (size, size) + raw
    return subprocess.run(["cjpeg", "-quality", "90"], input=ppm, stdout=subprocess.PIPE, check=True).stdout


# ---- the corpus ------------------------------------------------------------------------------

K10, K100, M1 = 10_000, 100_000, 1_000_000
# (shape, triangles, format, texture) per model; the seed is the row's index. Textures:
# (size, "png" | "jpeg"), glb only.
CORPUS = [
    ("blob", K10, "stl", None), ("torus", K10, "stl", None), ("terrain", K10, "stl", None),
    ("knot", K10, "obj", None), ("vase", K10, "obj", None), ("blob", K10, "obj", None),
    ("torus", K10, "ply", None), ("vase", K10, "ply", "colour"), ("terrain", K10, "ply", None),
    ("knot", K10, "glb", None), ("blob", K10, "glb", None), ("terrain", K10, "glb", None),
    ("torus", K10, "glb", (1024, "png")), ("blob", K10, "glb", (1024, "jpeg")),
    ("vase", K10, "glb", (2048, "png")), ("torus", K10, "glb", (2048, "jpeg")),
    ("terrain", K100, "stl", None), ("knot", K100, "stl", None), ("vase", K100, "stl", None),
    ("torus", K100, "obj", None), ("blob", K100, "obj", None), ("terrain", K100, "obj", None),
    ("blob", K100, "ply", "colour"), ("knot", K100, "ply", None), ("torus", K100, "ply", None),
    ("vase", K100, "glb", None), ("knot", K100, "glb", None), ("blob", K100, "glb", None),
    ("terrain", K100, "glb", (1024, "png")), ("blob", K100, "glb", (2048, "jpeg")),
    ("blob", M1, "stl", None), ("torus", M1, "glb", None),
]
CLASS = {K10: "10k", K100: "100k", M1: "1M"}


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: farm_corpus.py DIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    manifest = []
    for n, (shape, target, fmt, tex) in enumerate(CORPUS):
        seed = 1000 + n
        rnd = random.Random(seed * 7919)
        name = "%02d-%s-%s-%s" % (n, CLASS[target], shape, fmt if not isinstance(tex, tuple) else
                                  "%s-%s%d" % (fmt, tex[1], tex[0]))
        path = os.path.join(out, name + "." + fmt)
        s = build(shape, seed, target)
        texture = None
        if fmt == "stl":
            tris = write_stl(path, s, name)
        elif fmt == "obj":
            tris = write_obj(path, s, name, uvs=(n % 2 == 0))
        elif fmt == "ply":
            pal = [tuple(rnd.randrange(60, 256) for _ in range(3)) for _ in range(5)] if tex == "colour" else None
            tris = write_ply(path, s, name, pal)
            texture = "vertex colours" if pal else None
        else:
            colour = tuple(round(rnd.uniform(0.25, 0.95), 3) for _ in range(3))
            image = mime = None
            if isinstance(tex, tuple):
                size, kind = tex
                image = png_bytes(size, seed) if kind == "png" else jpeg_bytes(size, seed)
                mime = "image/png" if kind == "png" else "image/jpeg"
                texture = "%dx%d %s" % (size, size, kind)
            rep = (rnd.choice([2, 3, 4]), rnd.choice([1, 2])) if shape != "terrain" else (2, 2)
            tris = write_glb(path, s, name, colour, image, mime, rep)
        assert tris == s.triangles(), (name, tris, s.triangles())
        manifest.append({"file": os.path.basename(path), "format": fmt, "class": CLASS[target], "shape": shape,
                         "triangles": tris, "vertices": s.vertices(), "texture": texture,
                         "bytes": os.path.getsize(path)})
        print("%-36s %9d triangles %10d bytes%s" % (os.path.basename(path), tris, os.path.getsize(path),
                                                     "  " + texture if texture else ""), file=sys.stderr)
    with open(os.path.join(out, "manifest.json"), "w") as fh:
        json.dump({"generator": "tests/bench/farm_corpus.py", "models": manifest}, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
