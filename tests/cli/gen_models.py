#!/usr/bin/env python3
"""tests/cli/gen_models.py DIR [N] — writes N (default 50) varied meshes for the thumbnail farm:
tori, lumpy rocks, twisted columns, stepped towers, cones, stars and knots, in OBJ, ASCII STL,
binary STL and ASCII PLY (cycled), with different orientations and scales. Deterministic.
Used for the farm measurement in the README; standard library only."""
import math, os, random, struct, sys


def torus(R, r, n=48, m=24):
    v, f = [], []
    for i in range(n):
        for j in range(m):
            a, b = 2 * math.pi * i / n, 2 * math.pi * j / m
            v.append(((R + r * math.cos(b)) * math.cos(a), r * math.sin(b), (R + r * math.cos(b)) * math.sin(a)))
    for i in range(n):
        for j in range(m):
            p, q = i * m + j, ((i + 1) % n) * m + j
            p2, q2 = i * m + (j + 1) % m, ((i + 1) % n) * m + (j + 1) % m
            f += [(p, p2, q), (q, p2, q2)]
    return v, f


def sphere_like(rnd, rough, n=32, m=16, stretch=(1, 1, 1)):
    v, f = [], []
    bumps = [(rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(0.05, rough)) for _ in range(6)]
    for j in range(m + 1):
        for i in range(n):
            th, ph = math.pi * j / m, 2 * math.pi * i / n
            d = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            rad = 1 + sum(h * max(0, d[0] * x + d[1] * y + d[2] * z) ** 3 for x, y, z, h in bumps)
            v.append(tuple(rad * d[k] * stretch[k] for k in range(3)))
    for j in range(m):
        for i in range(n):
            a, b = j * n + i, j * n + (i + 1) % n
            c, d = a + n, b + n
            f += [(a, c, b), (b, c, d)]
    return v, f


def column(h, r, twist, sides, n=24):
    v, f = [], []
    for j in range(n + 1):
        y = h * j / n
        for i in range(sides):
            a = 2 * math.pi * i / sides + twist * j / n
            rr = r * (1 - 0.3 * y / h)
            v.append((rr * math.cos(a), y, rr * math.sin(a)))
    for j in range(n):
        for i in range(sides):
            a, b = j * sides + i, j * sides + (i + 1) % sides
            f += [(a, a + sides, b), (b, a + sides, b + sides)]
    top, bot = len(v), len(v) + 1
    v += [(0, h, 0), (0, 0, 0)]
    for i in range(sides):
        f += [(n * sides + i, top, n * sides + (i + 1) % sides), (i, (i + 1) % sides, bot)]
    return v, f


def boxes(rnd, k):
    v, f = [], []
    y = 0
    for s in range(k):
        w, h = rnd.uniform(0.4, 1.2) * (1 - s / (k + 1)), rnd.uniform(0.2, 0.8)
        x0, z0 = rnd.uniform(-0.2, 0.2), rnd.uniform(-0.2, 0.2)
        b = len(v)
        for c in range(8):
            v.append((x0 + (w if c & 1 else -w), y + (h if c & 2 else 0), z0 + (w if c & 4 else -w)))
        for q in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
            f += [(b + q[0], b + q[1], b + q[2]), (b + q[0], b + q[2], b + q[3])]
        y += h
    return v, f


def knot(p, q, n=160, m=12, r=0.18):
    v, f = [], []
    def c(t):
        rr = 0.6 + 0.3 * math.cos(q * t)
        return (rr * math.cos(p * t), 0.3 * math.sin(q * t), rr * math.sin(p * t))
    for i in range(n):
        t = 2 * math.pi * i / n
        a, b = c(t), c(t + 1e-3)
        tg = [b[k] - a[k] for k in range(3)]
        l = math.sqrt(sum(x * x for x in tg)); tg = [x / l for x in tg]
        up = (0, 1, 0)
        nx = [tg[1] * up[2] - tg[2] * up[1], tg[2] * up[0] - tg[0] * up[2], tg[0] * up[1] - tg[1] * up[0]]
        l = math.sqrt(sum(x * x for x in nx)) or 1; nx = [x / l for x in nx]
        bx = [tg[1] * nx[2] - tg[2] * nx[1], tg[2] * nx[0] - tg[0] * nx[2], tg[0] * nx[1] - tg[1] * nx[0]]
        for j in range(m):
            s = 2 * math.pi * j / m
            v.append(tuple(a[k] + r * (math.cos(s) * nx[k] + math.sin(s) * bx[k]) for k in range(3)))
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, ((i + 1) % n) * m + j
            a2, b2 = i * m + (j + 1) % m, ((i + 1) % n) * m + (j + 1) % m
            f += [(a, b, a2), (a2, b, b2)]
    return v, f


def transform(v, rnd):
    ax = rnd.uniform(-0.6, 0.6); s = rnd.uniform(0.3, 3.0)
    ca, sa = math.cos(ax), math.sin(ax)
    return [(s * x, s * (ca * y - sa * z) + 5 * s, s * (sa * y + ca * z)) for x, y, z in v]


def normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]; w = [c[k] - a[k] for k in range(3)]
    n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    l = math.sqrt(sum(x * x for x in n)) or 1
    return tuple(x / l for x in n)


def write(path, v, f):
    ext = path.rsplit('.', 1)[1]
    if ext == 'obj':
        with open(path, 'w') as o:
            o.writelines('v %.5f %.5f %.5f\n' % p for p in v)
            o.writelines('f %d %d %d\n' % (a + 1, b + 1, c + 1) for a, b, c in f)
    elif ext == 'ply':
        with open(path, 'w') as o:
            o.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n'
                    'element face %d\nproperty list uchar int vertex_indices\nend_header\n' % (len(v), len(f)))
            o.writelines('%.5f %.5f %.5f\n' % p for p in v)
            o.writelines('3 %d %d %d\n' % t for t in f)
    elif path.endswith('.bin.stl'):
        with open(path, 'wb') as o:
            o.write(b'umbra farm test'.ljust(80, b' ') + struct.pack('<I', len(f)))
            for t in f:
                a, b, c = (v[i] for i in t)
                o.write(struct.pack('<12fH', *normal(a, b, c), *a, *b, *c, 0))
    else:
        with open(path, 'w') as o:
            o.write('solid m\n')
            for t in f:
                a, b, c = (v[i] for i in t)
                o.write('facet normal %.4f %.4f %.4f\n outer loop\n' % normal(a, b, c))
                o.writelines('  vertex %.5f %.5f %.5f\n' % p for p in (a, b, c))
                o.write(' endloop\nendfacet\n')
            o.write('endsolid m\n')


def main():
    out, n = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 50
    os.makedirs(out, exist_ok=True)
    rnd = random.Random(7)
    makers = [
        lambda: torus(1, rnd.uniform(0.15, 0.5)),
        lambda: sphere_like(rnd, 0.6, stretch=(rnd.uniform(0.6, 1.4), rnd.uniform(0.5, 1.2), 1)),
        lambda: column(rnd.uniform(1.5, 4), rnd.uniform(0.3, 0.7), rnd.uniform(0, 3), rnd.choice([3, 4, 5, 6, 8])),
        lambda: boxes(rnd, rnd.randint(2, 6)),
        lambda: knot(rnd.choice([2, 3]), rnd.choice([3, 5])),
    ]
    exts = ['obj', 'stl', 'bin.stl', 'ply']
    for i in range(n):
        v, f = makers[i % len(makers)]()
        write(os.path.join(out, 'model%02d.%s' % (i, exts[(i // len(makers)) % len(exts)])), transform(v, rnd), f)


main()
