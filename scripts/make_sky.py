#!/usr/bin/env python3
"""Writes scenes/textures/sky.hdr, the environment map of scenes/env-materials.toml:
a procedural sky (a horizon-to-zenith gradient over a darker ground) with a bright
sun disk, 256 x 128 texels, equirectangular in gpu-render's (and Mitsuba 3's envmap)
convention: texel (x, y) looks along theta = pi (y + 1/2) / 128 from +y and
phi = 2 pi (x + 1/2) / 256, direction (sin phi sin theta, cos theta, -cos phi sin theta).

Made by us for this project (same licence as the repository, MIT OR Apache-2.0).
Pure Python, no dependencies; the output is a Radiance RGBE file with flat
(uncompressed) scanlines.

    python3 scripts/make_sky.py scenes/textures/sky.hdr
"""

import math
import struct
import sys

WIDTH, HEIGHT = 256, 128
# The sun: elevation and azimuth (phi) in degrees, angular radius and radiance.
SUN_ELEVATION, SUN_PHI = 35.0, 140.0
SUN_RADIUS, SUN_EDGE = 4.0, 1.5
SUN = (60.0, 54.0, 45.0)
HORIZON = (1.0, 0.9, 0.78)
ZENITH = (0.12, 0.28, 0.75)
GROUND = (0.22, 0.19, 0.16)
SUPERSAMPLES = 3


def direction(u, v):
    theta, phi = math.pi * v, 2.0 * math.pi * u
    s = math.sin(theta)
    return (math.sin(phi) * s, math.cos(theta), -math.cos(phi) * s)


def sky(d):
    x, y, z = d
    if y >= 0.0:
        t = math.sqrt(y)
        base = tuple(h + (zn - h) * t for h, zn in zip(HORIZON, ZENITH))
    else:
        base = GROUND
    e, p = math.radians(SUN_ELEVATION), math.radians(SUN_PHI)
    sun = (math.sin(p) * math.cos(e), math.sin(e), -math.cos(p) * math.cos(e))
    angle = math.degrees(math.acos(max(-1.0, min(1.0, x * sun[0] + y * sun[1] + z * sun[2]))))
    # A smooth edge from SUN_RADIUS - SUN_EDGE to SUN_RADIUS + SUN_EDGE (smoothstep).
    t = (SUN_RADIUS + SUN_EDGE - angle) / (2.0 * SUN_EDGE)
    t = max(0.0, min(1.0, t))
    w = t * t * (3.0 - 2.0 * t)
    return tuple(b + w * s for b, s in zip(base, SUN))


def rgbe(c):
    v = max(c)
    if v < 1e-32:
        return b"\0\0\0\0"
    m, e = math.frexp(v)
    scale = m * 256.0 / v
    return bytes([min(255, int(ch * scale)) for ch in c] + [e + 128])


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_sky.py OUTPUT.hdr")
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += f"-Y {HEIGHT} +X {WIDTH}\n".encode()
    n = SUPERSAMPLES
    for y in range(HEIGHT):
        for x in range(WIDTH):
            total = [0.0, 0.0, 0.0]
            for j in range(n):
                for i in range(n):
                    c = sky(direction((x + (i + 0.5) / n) / WIDTH, (y + (j + 0.5) / n) / HEIGHT))
                    total = [a + b for a, b in zip(total, c)]
            out += rgbe([t / (n * n) for t in total])
    with open(sys.argv[1], "wb") as f:
        f.write(out)


if __name__ == "__main__":
    main()
