#!/usr/bin/env python3
"""Writes the seed corpus of the photograph fuzz target image_file (fuzz/corpus/image_file/):
small synthetic PNG, TIFF, JPEG and DNG files, valid and near-valid, built here from the formats'
specifications (struct and zlib only; nothing from ../shared).

Run once after changing a seed (`/usr/bin/python3 fuzz/make_image_seeds.py`); the files are
committed.
"""

import pathlib
import struct
import zlib

CORPUS = pathlib.Path(__file__).resolve().parent / "corpus" / "image_file"


def write(name, data):
    CORPUS.mkdir(parents=True, exist_ok=True)
    (CORPUS / name).write_bytes(data)


# ---- PNG (ISO/IEC 15948) ---------------------------------------------------------------------


def chunk(kind, payload):
    body = kind + payload
    return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def png(width, height, depth, color, rows, extra=b"", after=b""):
    """rows: raw scanline bytes (without filter bytes)."""
    raw = b"".join(b"\x00" + r for r in rows)
    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, color, 0, 0, 0)) +
            extra + chunk(b"IDAT", zlib.compress(raw)) + after + chunk(b"IEND", b""))


def icc_grey(curve_entries):
    """A minimal ICC v2 grey display profile with a kTRC 'curv' of the given u16 entries."""
    header = bytearray(128)
    header[8:12] = struct.pack(">I", 0x02100000)
    header[12:16] = b"mntr"
    header[16:20] = b"GRAY"
    header[20:24] = b"XYZ "
    header[36:40] = b"acsp"
    header[68:80] = struct.pack(">iii", 0xF6D6, 0x10000, 0xD32D)
    wtpt = b"XYZ \0\0\0\0" + struct.pack(">iii", 0xF6D6, 0x10000, 0xD32D)
    trc = b"curv\0\0\0\0" + struct.pack(">I", len(curve_entries)) + b"".join(
        struct.pack(">H", v) for v in curve_entries)
    trc += b"\0" * (-len(trc) % 4)
    table_end = 128 + 4 + 2 * 12
    wtpt_at = table_end
    trc_at = wtpt_at + len(wtpt)
    table = struct.pack(">I", 2) + b"kTRC" + struct.pack(">II", trc_at, len(trc)) + \
        b"wtpt" + struct.pack(">II", wtpt_at, len(wtpt))
    profile = bytes(header) + table + wtpt + trc
    return struct.pack(">I", len(profile)) + profile[4:]


def ifd(entries, at, e="<"):
    """One IFD at offset `at`: entries (tag, type, count, value bytes) sorted by tag, values over
    4 bytes right after the table, no next IFD."""
    entries = sorted(entries)
    table = struct.pack(e + "H", len(entries))
    overflow = b""
    base = at + 2 + 12 * len(entries) + 4
    for tag, kind, count, data in entries:
        table += struct.pack(e + "HHI", tag, kind, count)
        if len(data) <= 4:
            table += data + b"\0" * (4 - len(data))
        else:
            table += struct.pack(e + "I", base + len(overflow))
            overflow += data + b"\0" * (len(data) % 2)
    return table + struct.pack(e + "I", 0) + overflow


def tiff_le(ifd0, pixels=b"", exif=None, big_endian=False):
    """A TIFF structure: header, one strip of pixels at offset 8, IFD0, an optional EXIF IFD."""
    e = ">" if big_endian else "<"

    pixels_at = 8
    ifd0_at = pixels_at + len(pixels)
    ifd0_at += ifd0_at % 2
    entries = list(ifd0)
    if pixels:
        entries.append((273, 4, 1, struct.pack(e + "I", pixels_at)))
        entries.append((279, 4, 1, struct.pack(e + "I", len(pixels))))
    if exif:
        entries.append((34665, 4, 1, struct.pack(e + "I", 0)))
        exif_at = ifd0_at + len(ifd(entries, ifd0_at, e))
        entries[-1] = (34665, 4, 1, struct.pack(e + "I", exif_at))
    head = (b"MM\0*" if big_endian else b"II*\0") + struct.pack(e + "I", ifd0_at)
    out = head + pixels + b"\0" * (ifd0_at - 8 - len(pixels)) + ifd(entries, ifd0_at, e)
    if exif:
        out += ifd(exif, exif_at, e)
    return out


def short(tag, *values, e="<"):
    return (tag, 3, len(values), b"".join(struct.pack(e + "H", v) for v in values))


def long_(tag, *values, e="<"):
    return (tag, 4, len(values), b"".join(struct.pack(e + "I", v) for v in values))


def rational(tag, *pairs, signed=False, e="<"):
    fmt = e + ("ii" if signed else "II")
    return (tag, 10 if signed else 5, len(pairs), b"".join(struct.pack(fmt, n, d) for n, d in pairs))


def byte_(tag, *values):
    return (tag, 1, len(values), bytes(values))


def ascii_(tag, text):
    data = text.encode() + b"\0"
    return (tag, 2, len(data), data)


EXIF = [rational(33434, (1, 125)), rational(33437, (56, 10)), short(34855, 200), short(40961, 1)]


def baseline(width, height, samples, bits, fmt, pixels, extra=(), exif=None, big_endian=False):
    e = ">" if big_endian else "<"
    ifd0 = [long_(256, width, e=e), long_(257, height, e=e), short(258, *([bits] * samples), e=e),
            short(259, 1, e=e), short(262, 2 if samples >= 3 else 1, e=e),
            short(277, samples, e=e), long_(278, height, e=e), short(284, 1, e=e),
            short(339, *([fmt] * samples), e=e)] + list(extra)
    return tiff_le(ifd0, pixels, exif, big_endian)


# PNG seeds.
write("grey8.png", png(4, 3, 8, 0, [bytes([0, 60, 120, 255])] * 3))
write("grey8_srgb.png", png(3, 2, 8, 0, [bytes([1, 128, 250])] * 2, chunk(b"sRGB", b"\x00")))
write("rgb16_gama.png", png(2, 2, 16, 2, [struct.pack(">6H", 0, 1000, 65535, 7, 30000, 65000)] * 2,
                            chunk(b"gAMA", struct.pack(">I", 45455))))
write("grey_alpha8.png", png(2, 1, 8, 4, [bytes([10, 255, 200, 0])]))
write("rgba8_exif.png", png(1, 1, 8, 6, [bytes([9, 99, 199, 128])],
                            chunk(b"eXIf", tiff_le([], b"", EXIF))))
write("grey16_sbit12.png", png(3, 1, 16, 0, [struct.pack(">3H", 1, 2049, 4095)],
                               chunk(b"sBIT", b"\x0c")))
LINEAR_ICC = zlib.compress(icc_grey([0, 65535]))  # a sampled identity curve
write("grey8_iccp_linear.png", png(2, 1, 8, 0, [bytes([0, 77])],
                                   chunk(b"iCCP", b"linear\0\0" + LINEAR_ICC)))
write("grey8_iccp_gamma.png", png(2, 1, 8, 0, [bytes([5, 77])],
                                  chunk(b"iCCP", b"g22\0\0" + zlib.compress(icc_grey([563])))))
write("grey16_truncated.png", png(8, 8, 16, 0, [bytes(range(16))] * 8)[:70])
write("palette.png", png(1, 1, 8, 3, [b"\x00"], chunk(b"PLTE", b"\x10\x20\x30")))

# TIFF seeds.
write("grey16_le.tif", baseline(3, 2, 1, 16, 1, struct.pack("<6H", 0, 1, 300, 40000, 65535, 12)))
write("grey16_be.tif", baseline(2, 1, 1, 16, 1, struct.pack(">2H", 64, 65535), big_endian=True))
write("rgb8_exif.tif", baseline(2, 1, 3, 8, 1, bytes([0, 10, 20, 250, 255, 128]),
                                [short(274, 6)], EXIF))
write("float32.tif", baseline(2, 2, 1, 32, 3, struct.pack("<4f", 0.0, 0.25, 1.0, 3.5)))
# A tiled TIFF: one 16 x 16 tile (RGB 16-bit) at offset 8 for a 3 x 2 image.
tile = bytes(16 * 16 * 6)
tiled_ifd = [long_(256, 3), long_(257, 2), short(258, 16, 16, 16), short(259, 1), short(262, 2),
             short(277, 3), short(284, 1), long_(322, 16), long_(323, 16), long_(324, 8),
             long_(325, len(tile))]


def tiled_tiff():
    ifd_at = 8 + len(tile)
    return b"II*\0" + struct.pack("<I", ifd_at) + tile + ifd(tiled_ifd, ifd_at)


write("rgb16_tiled.tif", tiled_tiff())
write("grey16_truncated.tif", baseline(16, 16, 1, 16, 1, bytes(512))[:300])
write("int16_signed.tif", baseline(1, 1, 1, 16, 2, b"\x01\x00"))

# JPEG seed: a 16 x 8 grey baseline JPEG whose two blocks have every coefficient 0 (ITU T.81:
# one-code Huffman tables, DC category 0 = code '0', AC EOB = code '0'; scan bits 0000 + 1111 pad).
DQT = b"\xff\xdb" + struct.pack(">H", 67) + b"\x00" + b"\x01" * 64
SOF0 = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, 8, 16, 1) + b"\x01\x11\x00"
DHT_DC = b"\xff\xc4" + struct.pack(">H", 20) + b"\x00" + bytes([1] + [0] * 15) + b"\x00"
DHT_AC = b"\xff\xc4" + struct.pack(">H", 20) + b"\x10" + bytes([1] + [0] * 15) + b"\x00"
SOS = b"\xff\xda" + struct.pack(">HB", 8, 1) + b"\x01\x00" + b"\x00\x3f\x00"
JPEG_BODY = DQT + SOF0 + DHT_DC + DHT_AC + SOS + b"\x0f" + b"\xff\xd9"
write("grey.jpg", b"\xff\xd8" + JPEG_BODY)
exif_payload = b"Exif\0\0" + tiff_le([short(274, 1)], b"", EXIF)
write("grey_exif.jpg", b"\xff\xd8" + b"\xff\xe1" + struct.pack(">H", len(exif_payload) + 2) +
      exif_payload + JPEG_BODY)
write("grey_truncated.jpg", (b"\xff\xd8" + JPEG_BODY)[:100])

# DNG seeds (DNG 1.4): LinearRaw RGB and a Bayer CFA image, 16-bit, 22 x 22 sites (LibRaw reads
# no image smaller than 22 x 22), exposure in an EXIF IFD.
N = 22
DNG_COMMON = [byte_(50706, 1, 4, 0, 0), byte_(50707, 1, 1, 0, 0),
              ascii_(50708, "roughscope seed"), ascii_(271, "roughscope"), ascii_(272, "seed"),
              rational(50721, *[(1, 1), (0, 1), (0, 1), (0, 1), (1, 1), (0, 1), (0, 1), (0, 1),
                                (1, 1)], signed=True),
              rational(50728, (1, 2), (1, 1), (4, 5)), short(50778, 21)]
DNG_EXIF = [rational(33434, (1, 60)), short(34855, 100)]
linear_pixels = struct.pack("<%dH" % (3 * N * N), *[(64 + 97 * i) % 4096 for i in range(3 * N * N)])
write("linear_raw.dng", tiff_le(
    [long_(254, 0), long_(256, N), long_(257, N), short(258, 16, 16, 16), short(259, 1),
     short(262, 34892), short(277, 3), long_(278, N), short(284, 1), short(50714, 64, 64, 64),
     long_(50717, 4095, 4095, 4095)] + DNG_COMMON, linear_pixels, DNG_EXIF))
bayer_pixels = struct.pack("<%dH" % (N * N), *[(100 + 251 * i) % 4096 for i in range(N * N)])
write("bayer.dng", tiff_le(
    [long_(254, 0), long_(256, N), long_(257, N), short(258, 16), short(259, 1),
     short(262, 32803), short(277, 1), long_(278, N), short(284, 1), short(33421, 2, 2),
     byte_(33422, 0, 1, 1, 2), byte_(50710, 0, 1, 2), short(50711, 1), short(50713, 2, 2),
     long_(50714, 60, 62, 64, 66), long_(50717, 4095)] + DNG_COMMON, bayer_pixels, DNG_EXIF))
write("bayer_truncated.dng", tiff_le(
    [long_(254, 0), long_(256, N), long_(257, N), short(258, 16), short(259, 1),
     short(262, 32803), short(277, 1), long_(278, N), short(284, 1), short(33421, 2, 2),
     byte_(33422, 0, 1, 1, 2), long_(50717, 4095)] + DNG_COMMON, bayer_pixels)[:600])

write("not_an_image.txt", b"theta_i,theta_s,phi_s\n30,30,180\n")
