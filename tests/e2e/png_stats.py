#!/usr/bin/env python3
"""Prints 'variance MEAN_ABS_DIFF' for PNG files without third-party modules.
Usage: png_stats.py A.png [B.png]  -> 'var=<variance of A's luminance> [diff=<mean abs difference A vs B>]'"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path + ": not a PNG"
    pos, idat, w, h, ctype = 8, b"", 0, 0, 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8, "8-bit only"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    bpp = {2: 3, 6: 4, 0: 1}[ctype]
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = bytearray(h * stride)
    prev = bytearray(stride)
    i = 0
    for y in range(h):
        f = raw[i]
        line = bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + ((a + b) >> 1)) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pr) & 255
        out[y * stride:(y + 1) * stride] = line
        prev = line
    lum = [sum(out[k:k + 3]) / 3.0 for k in range(0, len(out), bpp)] if bpp >= 3 else list(out)
    return lum


a = read_png(sys.argv[1])
mean = sum(a) / len(a)
var = sum((v - mean) ** 2 for v in a) / len(a)
msg = "var=%.2f" % var
if len(sys.argv) > 2:
    b = read_png(sys.argv[2])
    assert len(a) == len(b), "size mismatch"
    msg += " diff=%.3f" % (sum(abs(x - y) for x, y in zip(a, b)) / len(a))
print(msg)
