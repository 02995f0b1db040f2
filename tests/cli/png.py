#!/usr/bin/env python3
"""tests/cli/png.py — reads an 8-bit non-interlaced PNG (RGB or RGBA, what umbra writes) with
the standard library only, for the shell suites.

  png.py size FILE             -> "W H"
  png.py px FILE X Y           -> "R G B A" of pixel (X, Y) (A = 255 without alpha)
  png.py distinct FILE         -> number of distinct colours
  png.py tint FILE             -> "RED BLUE": pixels whose red (blue) beats both other channels by 40
  png.py opaque FILE           -> "W H" of the box around the pixels of alpha 255 (a transparent
                                  thumbnail's model: not its background, not its ground shadow)
"""
import struct, sys, zlib


def read(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise SystemExit('not a PNG: %s' % path)
    pos, idat, w = 8, b'', None
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype, _, _, interlace = struct.unpack('>IIBBBBB', body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise SystemExit('unsupported PNG layout')
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    bpp = 4 if ctype == 6 else 3
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def main():
    cmd, path = sys.argv[1], sys.argv[2]
    w, h, bpp, rows = read(path)
    if cmd == 'size':
        print(w, h)
    elif cmd == 'px':
        x, y = int(sys.argv[3]), int(sys.argv[4])
        p = rows[y][x * bpp:(x + 1) * bpp]
        print(*(list(p) + ([255] if bpp == 3 else [])))
    elif cmd == 'distinct':
        print(len({bytes(r[i:i + bpp]) for r in rows for i in range(0, w * bpp, bpp)}))
    elif cmd == 'tint':
        px = [r[i:i + 3] for r in rows for i in range(0, w * bpp, bpp)]
        print(sum(1 for p in px if p[0] > p[1] + 40 and p[0] > p[2] + 40),
              sum(1 for p in px if p[2] > p[0] + 40 and p[2] > p[1] + 40))
    elif cmd == 'opaque':
        if bpp != 4:
            raise SystemExit('opaque needs an RGBA PNG')
        pts = [(i // 4, y) for y, r in enumerate(rows) for i in range(3, w * 4, 4) if r[i] == 255]
        if not pts:
            print(0, 0)
        else:
            xs, ys = [p[0] for p in pts], [p[1] for p in pts]
            print(max(xs) - min(xs) + 1, max(ys) - min(ys) + 1)


if __name__ == '__main__':
    main()
