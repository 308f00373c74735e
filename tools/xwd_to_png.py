#!/usr/bin/env python3
"""Converts a TrueColor XWD image at 32 bits/pixel (what `Xvfb -fbdir DIR` keeps in
DIR/Xvfb_screen0, or `xwd -root`) to PNG, optionally cropped. Standard library only, so
screenshots need no ImageMagick.

  xwd_to_png.py Xvfb_screen0 out.png [--crop X,Y,W,H]

Prints the fraction of pixels that are not the most common colour (0 = a blank screen).
"""

import argparse
import collections
import struct
import sys
import zlib


def read_xwd(path):
    """(width, height, rows): rows = list of RGB bytes per line."""
    with open(path, "rb") as f:
        raw = f.read()
    fields = struct.unpack_from(">25I", raw, 0)
    header_size, version, fmt, _depth, width, height = fields[:6]
    byte_order, bits_per_pixel, bytes_per_line, ncolors = fields[7], fields[11], fields[12], fields[19]
    if version != 7 or fmt != 2 or bits_per_pixel != 32:
        raise ValueError("%s: only XWD v7 ZPixmap at 32 bits/pixel is supported" % path)
    start = header_size + 12 * ncolors
    rows = []
    for y in range(height):
        line = raw[start + y * bytes_per_line:start + y * bytes_per_line + 4 * width]
        # LSBFirst (0): B, G, R, X in memory for the usual 0xRRGGBB masks; MSBFirst: X, R, G, B.
        r, g, b = (line[2::4], line[1::4], line[0::4]) if byte_order == 0 else (line[1::4], line[2::4], line[3::4])
        rgb = bytearray(3 * width)
        rgb[0::3], rgb[1::3], rgb[2::3] = r, g, b
        rows.append(bytes(rgb))
    return width, height, rows


def write_png(path, width, height, rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + row for row in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("xwd")
    p.add_argument("png")
    p.add_argument("--crop", help="X,Y,W,H in pixels")
    a = p.parse_args()
    width, height, rows = read_xwd(a.xwd)
    if a.crop:
        x, y, w, h = (int(v) for v in a.crop.split(","))
        x, y = max(0, x), max(0, y)
        w, h = min(w, width - x), min(h, height - y)
        rows = [row[3 * x:3 * (x + w)] for row in rows[y:y + h]]
        width, height = w, h
    write_png(a.png, width, height, rows)
    pixels = collections.Counter(row[i:i + 3] for row in rows[::4] for i in range(0, len(row), 12))
    busy = 1.0 - pixels.most_common(1)[0][1] / max(1, sum(pixels.values()))
    print("%s: %dx%d, %.1f%% non-background pixels" % (a.png, width, height, 100 * busy))
    return 0


if __name__ == "__main__":
    sys.exit(main())
