#!/usr/bin/env python3
"""Counts the pixels of a PNG region darker than a threshold (every channel below it).

Usage: count_dark_pixels.py IMAGE.png X0 Y0 X1 Y1 [THRESHOLD]
(the region [X0, X1) x [Y0, Y1); the threshold out of 255, 40 by default).

Plain Python (zlib), no image library: the 8-bit RGB or RGBA PNGs gpu-render writes.
BENCHMARKS.md ("Normal-mapped metal without black rims") uses it.
"""

import struct
import sys
import zlib


def paeth(a, b, c):
    """The PNG Paeth predictor (PNG specification, section 9.4)."""
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def load(path):
    """The PNG's width, height, bytes per pixel and unfiltered rows."""
    data = open(path, "rb").read()
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, chunk = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", chunk[:10])
            if depth != 8 or colour not in (2, 6):
                sys.exit(f"{path}: only 8-bit RGB or RGBA PNGs are read")
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    raw = zlib.decompress(idat)
    bpp = 3 if colour == 2 else 4
    stride = width * bpp
    rows, previous, at = [], bytearray(stride), 0
    for _ in range(height):
        method, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for x in range(stride):
            left = line[x - bpp] if x >= bpp else 0
            up = previous[x]
            up_left = previous[x - bpp] if x >= bpp else 0
            predictor = [0, left, up, (left + up) // 2, paeth(left, up, up_left)][method]
            line[x] = (line[x] + predictor) & 255
        rows.append(line)
        previous = line
    return width, height, bpp, rows


if __name__ == "__main__":
    path = sys.argv[1]
    x0, y0, x1, y1 = (int(v) for v in sys.argv[2:6])
    threshold = int(sys.argv[6]) if len(sys.argv) > 6 else 40
    _, _, bpp, rows = load(path)
    total = (x1 - x0) * (y1 - y0)
    dark = sum(1 for y in range(y0, y1) for x in range(x0, x1)
               if max(rows[y][x * bpp:x * bpp + 3]) < threshold)
    print(f"{path}: {dark} of {total} pixels darker than {threshold}/255 "
          f"({100 * dark / total:.1f}%)")
