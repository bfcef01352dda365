#!/usr/bin/env python3
"""RGB565 little-endian 240x240 frame(s) -> PNG (pure Python, zlib), and a comparison.

  topng.py FRAME.rgb565 OUT.png [OTHER.rgb565 DIFF.png]
With OTHER: prints coverage of both (non-black pixels), pixels covered by only one, and pixels
whose colours differ by more than a few 565 steps; DIFF.png shows FRAME | OTHER | difference.
"""
import struct, sys, zlib

W = H = 240


def load(path):
    d = open(path, "rb").read()
    px = struct.unpack(f"<{W * H}H", d[:2 * W * H])
    return [((p >> 11) * 255 // 31, ((p >> 5) & 63) * 255 // 63, (p & 31) * 255 // 31) for p in px], px


def png(path, rows, w, h):
    raw = b"".join(b"\0" + bytes(c for px in r for c in px) for r in rows)
    def chunk(t, b):
        return struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


a, ra = load(sys.argv[1])
png(sys.argv[2], [a[y * W:(y + 1) * W] for y in range(H)], W, H)
print(f"{sys.argv[1]}: {sum(1 for p in ra if p)} non-black pixels")
if len(sys.argv) > 3:
    b, rb = load(sys.argv[3])
    print(f"{sys.argv[3]}: {sum(1 for p in rb if p)} non-black pixels")
    only_a = sum(1 for p, q in zip(ra, rb) if p and not q)
    only_b = sum(1 for p, q in zip(ra, rb) if q and not p)
    both = [(p, q) for p, q in zip(a, b) if p != (0, 0, 0) and q != (0, 0, 0)]
    far = sum(1 for p, q in both if max(abs(x - y) for x, y in zip(p, q)) > 24)
    print(f"only in first: {only_a}, only in second: {only_b}, in both: {len(both)}, "
          f"of which differ by > 24/255 in a channel: {far}")
    diff = [tuple(min(255, 4 * abs(x - y)) for x, y in zip(p, q)) for p, q in zip(a, b)]
    rows = [a[y * W:(y + 1) * W] + [(255, 0, 255)] * 4 + b[y * W:(y + 1) * W] + [(255, 0, 255)] * 4
            + diff[y * W:(y + 1) * W] for y in range(H)]
    png(sys.argv[4], rows, 3 * W + 8, H)
