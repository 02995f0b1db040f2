#!/usr/bin/env python3
"""tests/cli/contact_sheet.py OUT.png COLS SCALE IMAGE.png... — a contact sheet of thumbnails
(8-bit RGB/RGBA PNGs of one size, e.g. a farm's output), each shrunk by SCALE (box filter) and
flattened on white. Standard library only; for docs/ pictures."""
import struct, sys, zlib
sys.path.insert(0, __file__.rsplit('/', 1)[0])
from png import read  # noqa: E402  (tests/cli/png.py)


def main():
    out, cols, k, files = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4:]
    imgs = [read(f) for f in files]
    w, h = imgs[0][0] // k, imgs[0][1] // k
    rows = (len(imgs) + cols - 1) // cols
    W, H = cols * w, rows * h
    sheet = [bytearray(b'\xff' * (W * 3)) for _ in range(H)]
    for n, (iw, ih, bpp, px) in enumerate(imgs):
        ox, oy = (n % cols) * w, (n // cols) * h
        for y in range(h):
            for x in range(w):
                acc = [0, 0, 0]
                for dy in range(k):
                    row = px[y * k + dy]
                    for dx in range(k):
                        p = row[(x * k + dx) * bpp:(x * k + dx) * bpp + bpp]
                        a = p[3] / 255 if bpp == 4 else 1
                        for c in range(3):
                            acc[c] += p[c] * a + 255 * (1 - a)
                sheet[oy + y][(ox + x) * 3:(ox + x) * 3 + 3] = bytes(int(v / (k * k) + 0.5) for v in acc)
    raw = b''.join(b'\x00' + bytes(r) for r in sheet)
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))
    with open(out, 'wb') as o:
        o.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', W, H, 8, 2, 0, 0, 0)) +
                chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))


main()
