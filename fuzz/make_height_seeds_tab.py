#!/usr/bin/env python3
"""Writes the seed corpus of the height-file fuzz targets height_csv, height_sdf, height_png,
height_tiff and height_raw (fuzz/corpus/<target>/): small synthetic files, valid and near-valid,
built here from the formats' specifications (struct and zlib only; nothing from ../shared).

Run once after changing a seed (`python3 fuzz/make_height_seeds_tab.py`); the files are committed.
"""

import math
import pathlib
import struct
import zlib

CORPUS = pathlib.Path(__file__).resolve().parent / "corpus"


def write(target, name, data):
    path = CORPUS / target / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data.encode("utf-8") if isinstance(data, str) else data)


# ---- CSV matrix and XYZ ----------------------------------------------------------------------
write("height_csv", "matrix_header.csv",
      "# dx_um = 0.5\n# dy_um = 0.25\n# unit = nm\n# x_offset_um = -1\n1,2,3\n4,,NaN\n7,8,9\n")
write("height_csv", "matrix_gwyddion.txt",
      "# Channel: Height\n# Width: 4.000 \u00b5m\n# Height: 2.000 \u00b5m\n# Value units: m\n"
      "1e-9\t2e-9\n3e-9\t4e-9\n")
write("height_csv", "matrix_semicolon.csv", "1.5;-2;3e-1\r\n4;5;6\r\n")
write("height_csv", "matrix_ragged.csv", "1,2\n3\n")
write("height_csv", "xyz_grid.xyz",
      "# unit = mm\n2 0.5 6\n0 0 1\n1 0 2\n2 0 3\n0 0.5 NaN\n")
write("height_csv", "xyz_offgrid.xyz", "0 0 1\n1 0 2\n2.5 0 3\n")
# A UTF-8 byte-order mark at the start is skipped (docs/input-files.md).
write("height_csv", "matrix_bom.csv", "\ufeff# dx_um = 2\r\n1,2\r\n3,NaN\r\n")
write("height_csv", "xyz_bom.xyz", "\ufeff0 0 1\n1 0 2\n0 1 3\n1 1 4\n")

# ---- SDF -------------------------------------------------------------------------------------


def sdf_binary(nx, ny, xs, ys, zs, dtype, fmt, values, trailer=b""):
    head = (b"bISO-1.0" + b"HandMade  " + b"010120250000" * 2 +
            struct.pack("<HHdddd", nx, ny, xs, ys, zs, 0.0) + bytes([0, dtype, 0]))
    return head + struct.pack("<" + fmt * len(values), *values) + trailer


write("height_sdf", "binary_double.sdf",
      sdf_binary(3, 2, 1e-6, 1e-6, 1e-6, 7, "d", [0.1, 0.2, math.nan, -1.5, 2.0, 3.0],
                 b"*\ndx_um = 1\nx_offset_um = 5\n*\n"))
write("height_sdf", "binary_int16.sdf",
      sdf_binary(2, 2, 2e-6, 4e-6, 1e-9, 5, "h", [1, -2, -32768, 300]))
write("height_sdf", "binary_float.sdf", sdf_binary(2, 1, 1e-6, 1e-6, 1e-3, 3, "f", [0.5, 1.0]))
write("height_sdf", "binary_truncated.sdf",
      sdf_binary(4, 4, 1e-6, 1e-6, 1e-6, 7, "d", [1.0, 2.0]))
write("height_sdf", "ascii_int16.sdf",
      "aISO-1.0\nManufacID   = HandMade\nCreateDate  = 010120250000\nModDate     = 010120250000\n"
      "NumPoints   = 3\nNumProfiles = 2\nXscale      = 5.0E-07\nYscale      = 5.0E-07\n"
      "Zscale      = 1.0E-09\nZresolution = -1\nCompression = 0\nDataType    = 5\n"
      "CheckType   = 0\n*\n10 20 30\n-40 -32768 60\n*\nOPERATOR = nobody\n*\n")
write("height_sdf", "ascii_double.sdf",
      "aISO-1.0\nNumPoints = 2\nNumProfiles = 2\nXscale = 1e-06\nYscale = 1e-06\n"
      "Zscale = 1e-06\nDataType = 7\n*\n0.5 NaN\n-1 2\n*\ndx_um = 1\ny_offset_um = 3\n*\n")

write("height_sdf", "ascii_bom.sdf",
      "\ufeffaISO-1.0\nNumPoints = 2\nNumProfiles = 1\nXscale = 1e-06\nYscale = 1e-06\n"
      "Zscale = 1e-06\nDataType = 7\n*\n0.5 -1\n*\n")

# ---- PNG -------------------------------------------------------------------------------------


def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(
        ">I", zlib.crc32(kind + data) & 0xffffffff)


def png_grey(width, height, depth, counts, interlace=0):
    raw = b""
    for y in range(height):
        raw += b"\0"
        for x in range(width):
            c = counts[y * width + x]
            raw += struct.pack(">H", c) if depth == 16 else bytes([c])
    ihdr = struct.pack(">IIBBBBB", width, height, depth, 0, 0, 0, interlace)
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr) +
            png_chunk(b"IDAT", zlib.compress(raw)) + png_chunk(b"IEND", b""))


write("height_png", "grey16.png", png_grey(4, 3, 16, [i * 4000 for i in range(12)]))
write("height_png", "grey8.png", png_grey(3, 2, 8, [0, 50, 100, 150, 200, 250]))
write("height_png", "grey16_truncated.png", png_grey(8, 8, 16, list(range(64)))[:70])

# ---- TIFF ------------------------------------------------------------------------------------


def tiff(order, width, height, bits, sample_format, pixels):
    e = "<" if order == b"II" else ">"
    magic = order + struct.pack(e + "H", 42)
    entries = [(256, 4, width), (257, 4, height), (258, 3, bits), (259, 3, 1), (262, 3, 1),
               (273, 4, 8), (277, 3, 1), (278, 4, height), (279, 4, len(pixels)),
               (339, 3, sample_format)]
    ifd = struct.pack(e + "H", len(entries))
    for tag, kind, value in entries:
        field = struct.pack(e + "H", value) + b"\0\0" if kind == 3 else struct.pack(e + "I", value)
        ifd += struct.pack(e + "HHI", tag, kind, 1) + field
    ifd += struct.pack(e + "I", 0)
    return magic + struct.pack(e + "I", 8 + len(pixels)) + pixels + ifd


write("height_tiff", "uint16_le.tif",
      tiff(b"II", 2, 2, 16, 1, struct.pack("<4H", 0, 1, 65535, 300)))
write("height_tiff", "float32_be.tif",
      tiff(b"MM", 3, 1, 32, 3, struct.pack(">3f", 1.5, -2.25, math.nan)))
write("height_tiff", "float64_le.tif", tiff(b"II", 2, 1, 64, 3, struct.pack("<2d", 0.1, 7.0)))
write("height_tiff", "uint8_be.tif", tiff(b"MM", 2, 1, 8, 1, b"\x02\xff"))

# ---- raw (byte 0: bit 0 float32, bit 1 big endian, bit 2 wrong ny; byte 1: nx - 1) ----------
write("height_raw", "f64_le_3x2.raw", bytes([0, 2]) + struct.pack("<6d", 1, 2, 3, 4, math.nan, 6))
write("height_raw", "f32_be_2x2.raw", bytes([3, 1]) + struct.pack(">4f", 0.5, -1, math.inf, 8))
write("height_raw", "f64_wrong_size.raw", bytes([4, 1]) + struct.pack("<4d", 1, 2, 3, 4))
