"""What the bench scripts do with the command's PFM images: read them,
measure one against a reference, and write PNGs (still or animated)
through the same filmic curve and sRGB as the command's PNGs."""
import math
import struct
import zlib


def pfm(path):
    """(width, height, values): RGB floats, rows bottom to top as stored."""
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        v = struct.unpack(('<' if scale < 0 else '>') + 'f' * (w * h * 3), f.read())
    return w, h, v


def rel_rmse(img, ref):
    """RMSE per value, relative to the reference's value (+0.01)."""
    return math.sqrt(sum(((a - b) / (b + 0.01)) ** 2 for a, b in zip(img, ref)) / len(ref))


def code(x):
    """A linear value as 8-bit sRGB after the filmic curve (fr_filmic)."""
    x = max(x, 0.0)
    x = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)
    if x >= 1.0:
        return 255
    s = 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055
    return int(s * 255 + 0.5)


def png_rows(panels, cols):
    """Filtered PNG scanlines of a grid of equal PFM images, cols wide, top row first."""
    w, h = panels[0][0], panels[0][1]
    rows = []
    for gy in range(len(panels) // cols):
        for y in range(h):  # PFM rows run bottom to top
            row = bytearray([0])
            for gx in range(cols):
                v = panels[cols * gy + gx][2]
                base = (h - 1 - y) * w * 3
                row += bytes(code(c) for c in v[base:base + 3 * w])
            rows.append(bytes(row))
    return b"".join(rows)


def _chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)


def _header(w, h):
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))


def write_png(path, panels, cols):
    """The panels as one PNG grid, cols wide."""
    w, h = panels[0][0], panels[0][1]
    data = _header(cols * w, len(panels) // cols * h)
    data += _chunk(b"IDAT", zlib.compress(png_rows(panels, cols), 9)) + _chunk(b"IEND", b"")
    open(path, "wb").write(data)


def write_apng(path, frames, delay_tenths=1):
    """The frames as an animated PNG, looping, delay_tenths / 10 s each."""
    w, h = frames[0][0], frames[0][1]
    data = _header(w, h) + _chunk(b"acTL", struct.pack(">II", len(frames), 0))
    seq = 0
    for i, f in enumerate(frames):
        data += _chunk(b"fcTL", struct.pack(">IIIIIHHBB", seq, w, h, 0, 0, delay_tenths, 10, 0, 0))
        seq += 1
        z = zlib.compress(png_rows([f], 1), 9)
        if i == 0:
            data += _chunk(b"IDAT", z)
        else:
            data += _chunk(b"fdAT", struct.pack(">I", seq) + z)
            seq += 1
    open(path, "wb").write(data + _chunk(b"IEND", b""))
