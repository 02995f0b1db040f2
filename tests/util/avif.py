#!/usr/bin/env python3
"""tests/util/avif.py — checks umbra's AVIF answers for the shell suites, with libavif's own
avifdec (Debian libavif-bin; not umbra's code).

  avif.py info FILE          -> "W H lossless|lossy alpha|opaque" from `avifdec --info`: lossless
                                is what umbra writes for it (4:4:4, identity matrix: RGB coded
                                as is), lossy anything else; exit 1 when avifdec cannot read it
  avif.py compare AVIF PNG   -> "PSNR MAXALPHA": the AVIF decoded by avifdec against the PNG, as
                                tests/util/webp.py compare does (RGB PSNR over the pixels not fully
                                transparent, "inf" when equal; the largest alpha difference)
"""
import os, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'cli'))
import png  # noqa: E402
import webp  # noqa: E402


def info(path):
    r = subprocess.run(['avifdec', '--info', path], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit('avifdec cannot read it: ' + (r.stderr or r.stdout).strip()[-200:])
    fields = {}
    for line in r.stdout.splitlines():
        if line.startswith(' * ') and ':' in line:
            k, v = line[3:].split(':', 1)
            fields[k.strip()] = v.strip()
    w, h = fields['Resolution'].split('x')
    lossless = fields.get('Format') == 'YUV444' and fields.get('Matrix Coeffs.') == '0'
    alpha = fields.get('Alpha', 'Absent') != 'Absent'
    return int(w), int(h), 'lossless' if lossless else 'lossy', alpha


def decode(path):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, 'decoded.png')
        r = subprocess.run(['avifdec', '--depth', '8', path, out], capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit('avifdec could not decode it: ' + (r.stderr or r.stdout).strip()[-200:])
        w, h, bpp, rows = png.read(out)
    rgba = bytearray()
    for row in rows:
        for x in range(w):
            px = row[x * bpp:(x + 1) * bpp]
            rgba += bytes(px[:3]) + bytes([px[3] if bpp == 4 else 255])
    return w, h, bytes(rgba)


def main():
    if sys.argv[1] == 'info':
        w, h, kind, alpha = info(sys.argv[2])
        print(w, h, kind, 'alpha' if alpha else 'opaque')
        return
    w, h, rgba = decode(sys.argv[2])
    webp.compare(w, h, rgba, sys.argv[3])


if __name__ == '__main__':
    main()
