#!/usr/bin/env python3
"""tests/util/webp.py — checks umbra's WebP answers for the shell suites.

  webp.py info FILE          -> "W H lossless|lossy alpha|opaque", from the RIFF container's
                                chunks (standard library; exit 1 when FILE is no WebP)
  webp.py compare WEBP PNG   -> "PSNR MAXALPHA": the WebP decoded by the system's libwebp
                                (libwebp.so.7, through ctypes; not umbra's code) against the PNG
                                (tests/cli/png.py), RGB PSNR in dB ("inf" when equal) over
                                the pixels not fully transparent in both (a lossy encoder may
                                give those any colour), and the largest alpha difference. Exit 1
                                on a size mismatch.
"""
import ctypes, ctypes.util, math, os, struct, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'cli'))
import png  # noqa: E402


def info(data):
    if len(data) < 30 or data[:4] != b'RIFF' or data[8:12] != b'WEBP':
        raise SystemExit('not a WebP')
    pos, alpha, kind, w, h = 12, False, None, 0, 0
    while pos + 8 <= len(data):
        tag, n = data[pos:pos + 4], struct.unpack('<I', data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + n]
        if tag == b'VP8X':
            alpha = bool(body[0] & 0x10)
        elif tag == b'ALPH':
            alpha = True
        elif tag == b'VP8L':   # signature 0x2f, then 14-bit width-1, height-1, alpha_is_used
            bits = struct.unpack('<I', body[1:5])[0]
            kind, w, h = 'lossless', (bits & 0x3fff) + 1, ((bits >> 14) & 0x3fff) + 1
            alpha = alpha or bool(bits >> 28 & 1)
        elif tag == b'VP8 ':   # frame tag (3 bytes), start code (3), 14-bit width and height
            kind = 'lossy'
            w, h = struct.unpack('<HH', body[6:10])
            w, h = w & 0x3fff, h & 0x3fff
        pos += 8 + n + (n & 1)
    if not kind:
        raise SystemExit('no VP8/VP8L chunk')
    return w, h, kind, alpha


def decode(data):
    lib = ctypes.CDLL(ctypes.util.find_library('webp') or 'libwebp.so.7')
    lib.WebPDecodeRGBA.restype = ctypes.POINTER(ctypes.c_uint8)
    lib.WebPDecodeRGBA.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(ctypes.c_int),
                                   ctypes.POINTER(ctypes.c_int)]
    w, h = ctypes.c_int(), ctypes.c_int()
    p = lib.WebPDecodeRGBA(data, len(data), ctypes.byref(w), ctypes.byref(h))
    if not p:
        raise SystemExit('libwebp could not decode it')
    out = bytes(p[:w.value * h.value * 4])
    lib.WebPFree(p)
    return w.value, h.value, out


def compare(w, h, rgba, png_path):
    """Prints "PSNR MAXALPHA" of decoded RGBA8 pixels against the PNG (see the module's help);
    exit 1 on a size mismatch. Also used by tests/util/avif.py."""
    pw, ph, bpp, rows = png.read(png_path)
    if (w, h) != (pw, ph):
        print('size %dx%d, PNG %dx%d' % (w, h, pw, ph))
        sys.exit(1)
    se, n, amax = 0, 0, 0
    for y in range(h):
        for x in range(w):
            a, b = rgba[4 * (y * w + x):4 * (y * w + x) + 4], rows[y][x * bpp:(x + 1) * bpp]
            b_alpha = b[3] if bpp == 4 else 255
            amax = max(amax, abs(a[3] - b_alpha))
            if a[3] or b_alpha:
                se += sum((a[c] - b[c]) ** 2 for c in range(3))
                n += 1
    mse = se / (3.0 * max(n, 1))
    print('inf' if mse == 0 else '%.1f' % (10 * math.log10(255 * 255 / mse)), amax)


def main():
    cmd = sys.argv[1]
    data = open(sys.argv[2], 'rb').read()
    if cmd == 'info':
        w, h, kind, alpha = info(data)
        print(w, h, kind, 'alpha' if alpha else 'opaque')
        return
    w, h, rgba = decode(data)
    compare(w, h, rgba, sys.argv[3])


if __name__ == '__main__':
    main()
