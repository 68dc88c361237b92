#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The example photographs of docs/guide.md: SYNTHETIC frames of a 150 mm drum's face, made here
(no camera), of known answer, for trying `granucal measure` before using your own photos.

    python3 make_photos.py        # rewrites the PNGs in this folder (deterministic)

Each frame: a light drum face inside a dark rim on a grey surround, dark powder below a straight
surface at ANGLE degrees filling FILL of the circle, light falling off across the picture, grey
noise. Edges are anti-aliased (4 x 4 samples per pixel). The truth of each frame is in FRAMES.
"""
import math
import random
import struct
import zlib

W, H, CX, CY, R, RIM = 360, 340, 178.4, 171.2, 145.0, 9.0
POWDER, DRUM, RIM_GREY, SURROUND, NOISE, GRADIENT = 70.0, 210.0, 45.0, 150.0, 3.0, 0.15

# name: (surface angle in degrees, fill fraction of the circle, noise seed)
FRAMES = {
    "powder_4rpm_1": (35.4, 0.368, 1), "powder_4rpm_2": (34.6, 0.372, 2),
    "powder_40rpm_1": (38.6, 0.392, 3), "powder_40rpm_2": (39.4, 0.398, 4),
    "steel_4rpm_1": (31.3, 0.366, 5), "steel_4rpm_2": (30.7, 0.370, 6),
    "steel_40rpm_1": (33.2, 0.388, 7), "steel_40rpm_2": (33.8, 0.392, 8),
}


def surface_offset(fill):
    """Offset t of the surface along its upward normal (unit disc) with fill * pi of the disc below."""
    lo, hi = -1.0, 1.0
    for _ in range(60):
        t = 0.5 * (lo + hi)
        below = math.pi - math.acos(t) + t * math.sqrt(1 - t * t)
        lo, hi = (lo, t) if below > fill * math.pi else (t, hi)
    return 0.5 * (lo + hi)


def grey_at(x, y, nx, ny, t):
    u, v = (x - CX) / R, (CY - y) / R  # y up
    rho = math.hypot(u, v) * R
    if rho > R + RIM:
        return SURROUND
    if rho > R:
        return RIM_GREY
    return POWDER if u * nx + v * ny < t else DRUM


def render(angle, fill, seed):
    rng = random.Random(seed)
    a = math.radians(angle)
    nx, ny, t = -math.sin(a), math.cos(a), surface_offset(fill)
    rows = []
    for j in range(H):
        row = bytearray([0])  # PNG filter byte: none
        for i in range(W):
            g = sum(grey_at(i + (p + 0.5) / 4, j + (q + 0.5) / 4, nx, ny, t) for p in range(4) for q in range(4)) / 16
            g *= 1 - GRADIENT * i / W
            row.append(max(0, min(255, int(round(g + rng.gauss(0, NOISE))))))
        rows.append(bytes(row))
    return b"".join(rows)


def png(path, pixels):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    head = struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0)  # 8-bit greyscale
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(pixels, 9)) + chunk(b"IEND", b""))


if __name__ == "__main__":
    for name, (angle, fill, seed) in FRAMES.items():
        png(name + ".png", render(angle, fill, seed))
        print(f"{name}.png: surface {angle} deg, {100 * fill:.1f} % of the circle")
