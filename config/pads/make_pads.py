#!/usr/bin/python3
"""Writes the example landing-pad designs of config/pads (docs/track.md, "Landing: the user's own pad").

Each design is the pad's square seen from above (column = pad +x, row = pad -y), white paint on the
dark pad, 256 x 256 px, as PNG (the pose estimator's pad.image) and as binary PGM (the simulator's
world.helipad_image, which links no image codec). Needs only numpy (Debian: python3-numpy):
    /usr/bin/python3 config/pads/make_pads.py [OUT_DIR]
"""
import os
import struct
import sys
import zlib

import numpy as np

N = 256
# Pad coordinates of every pixel centre, normalised by the side: x to the right, y up, in (-0.5, 0.5).
x = (np.arange(N) + 0.5) / N - 0.5
X, Y = np.meshgrid(x, -x)
R = np.hypot(X, Y)


def ring_cross():
    """A ring and a cross: 90 deg symmetric (yaw modulo 90 deg)."""
    ring = (R > 0.30) & (R < 0.38)
    cross = ((np.abs(X) < 0.04) | (np.abs(Y) < 0.04)) & (np.maximum(np.abs(X), np.abs(Y)) < 0.24)
    return ring | cross


def logo():
    """An asymmetric logo: an L, a triangle and a dot (no symmetry: yaw over the full turn)."""
    ell = ((X > -0.32) & (X < -0.20) & (Y > -0.30) & (Y < 0.30)) | ((X > -0.32) & (X < 0.05) & (Y > -0.30) & (Y < -0.18))
    tri = (X > 0.02) & (Y > -0.05) & ((X - 0.02) / 0.32 + (Y + 0.05) / 0.37 < 1)
    dot = np.hypot(X - 0.24, Y + 0.22) < 0.08
    return ell | tri | dot


def checker():
    """A 4 x 4 checkerboard inside a dark frame: 180 deg symmetric (yaw modulo 180 deg)."""
    inside = np.maximum(np.abs(X), np.abs(Y)) < 0.38
    i = np.floor((X + 0.38) / 0.19).astype(int)
    j = np.floor((Y + 0.38) / 0.19).astype(int)
    return inside & ((i + j) % 2 == 0)


def write_png(path, img):
    raw = b"".join(b"\x00" + img[r].tobytes() for r in range(img.shape[0]))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", img.shape[1], img.shape[0], 8, 0, 0, 0, 0)  # 8-bit gray
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def write_pgm(path, img):
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (img.shape[1], img.shape[0]) + img.tobytes())


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for name, design in (("ring_cross", ring_cross), ("logo", logo), ("checker", checker)):
        img = np.where(design(), 255, 0).astype(np.uint8)
        write_png(os.path.join(out, name + ".png"), img)
        write_pgm(os.path.join(out, name + ".pgm"), img)


if __name__ == "__main__":
    main()
