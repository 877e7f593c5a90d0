#!/usr/bin/env python3
"""Writes the seed files of the x3p, gwy and gsf fuzz targets (fuzz/corpus/height_{x3p,gwy,gsf}/).

Independent minimal writers from the formats' descriptions (ISO 5436-2 main.xml in a zip with its
MD5 checksums; the Gwyddion GWYP serialization; the Gwyddion Simple Field header, NUL padding and
float32 data), standard library only. Deterministic: rerunning rewrites the same bytes.

    python3 fuzz/make_height_seeds_x3p.py
"""
import hashlib
import math
import pathlib
import struct
import zipfile
import io

ROOT = pathlib.Path(__file__).resolve().parent / "corpus"
EPOCH = (1980, 1, 1, 0, 0, 0)


def x3p(nx, ny, ztype, values, valid=None, datalist=False, folder=""):
    fmt = {"D": "<d", "F": "<f", "L": "<i", "I": "<h"}[ztype]
    data = b"".join(struct.pack(fmt, v) for v in values)
    link = ""
    if datalist:
        items = "".join("<Datum/>" if (valid and not valid[i]) else f"<Datum>{v!r}</Datum>"
                        for i, v in enumerate(values))
        record3_data = f"<DataList>{items}</DataList>"
    else:
        extra = ""
        bits = None
        if valid is not None:
            bits = bytearray((len(values) + 7) // 8)
            for i, ok in enumerate(valid):
                if ok:
                    bits[i // 8] |= 1 << (i % 8)
            extra = ("<ValidPointsLink>bindata/valid.bin</ValidPointsLink><MD5ChecksumValidPoints>"
                     f"{hashlib.md5(bits).hexdigest()}</MD5ChecksumValidPoints>")
        record3_data = ("<DataLink><PointDataLink>bindata/data.bin</PointDataLink>"
                        f"<MD5ChecksumPointData>{hashlib.md5(data).hexdigest()}"
                        f"</MD5ChecksumPointData>{extra}</DataLink>")
    zinc = "<Increment>1e-9</Increment><Offset>1e-6</Offset>" if ztype in "IL" else ""
    xml = ("<?xml version=\"1.0\" encoding=\"UTF-8\"?>"
           "<p:ISO5436_2 xmlns:p=\"http://www.opengps.eu/2008/ISO5436_2\"><Record1>"
           "<Revision>ISO5436 - 2000</Revision>"
           f"<FeatureType>{'PRF' if ny == 1 else 'SUR'}</FeatureType><Axes>"
           "<CX><AxisType>I</AxisType><DataType>D</DataType><Increment>2.5e-7</Increment>"
           "<Offset>0</Offset></CX><CY><AxisType>I</AxisType><DataType>D</DataType>"
           "<Increment>5e-7</Increment><Offset>0</Offset></CY>"
           f"<CZ><AxisType>A</AxisType><DataType>{ztype}</DataType>{zinc}</CZ></Axes></Record1>"
           f"<Record3><MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ>"
           f"</MatrixDimension>{record3_data}</Record3>"
           "<Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4></p:ISO5436_2>")
    xml_bytes = xml.encode()
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        def add(name, payload):
            info = zipfile.ZipInfo(folder + name, EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, payload)
        add("main.xml", xml_bytes)
        add("md5checksum.hex", hashlib.md5(xml_bytes).hexdigest() + " *main.xml\n")
        if not datalist:
            add("bindata/data.bin", data)
            if valid is not None:
                add("bindata/valid.bin", bytes(bits))
    return out.getvalue()


def gwy_object(name, components):
    return name.encode() + b"\0" + struct.pack("<I", len(components)) + components


def comp(key, kind, payload):
    return key.encode() + b"\0" + kind.encode() + payload


def gwy(nx, ny, values, mask=None):
    def field(vals, unit_z):
        unit = lambda u: gwy_object("GwySIUnit", comp("unitstr", "s", u.encode() + b"\0"))
        return gwy_object("GwyDataField",
                          comp("xres", "i", struct.pack("<i", nx)) +
                          comp("yres", "i", struct.pack("<i", ny)) +
                          comp("xreal", "d", struct.pack("<d", nx * 1e-6)) +
                          comp("yreal", "d", struct.pack("<d", ny * 1e-6)) +
                          comp("si_unit_xy", "o", unit("m")) + comp("si_unit_z", "o", unit(unit_z)) +
                          comp("data", "D", struct.pack("<I", len(vals)) +
                               b"".join(struct.pack("<d", v) for v in vals)))
    items = comp("/0/data/title", "s", b"seed\0") + comp("/0/data", "o", field(values, "m"))
    if mask is not None:
        items += comp("/0/mask", "o", field(mask, ""))
    return b"GWYP" + gwy_object("GwyContainer", items)


def gsf(nx, ny, values):
    header = (f"Gwyddion Simple Field 1.0\nXRes = {nx}\nYRes = {ny}\nXReal = {nx * 0.5}\n"
              f"YReal = {ny * 0.5}\nXYUnits = um\nZUnits = um\nTitle = seed\n").encode()
    header += b"\0" * (4 - len(header) % 4)
    return header + b"".join(struct.pack("<f", v) for v in values)


def main():
    wave = [math.sin(0.7 * i) * 1e-6 for i in range(12)]
    seeds = {
        "height_x3p": {
            "double_4x3.x3p": x3p(4, 3, "D", wave),
            "float_valid_4x3.x3p": x3p(4, 3, "F", wave, valid=[i != 5 for i in range(12)]),
            "int32_profile.x3p": x3p(6, 1, "L", [1, -2, 300, 4, 5, 0]),
            "int16_nested.x3p": x3p(2, 2, "I", [1, 2, 3, 4], folder="top/"),
            "datalist_3x2.x3p": x3p(3, 2, "D", wave[:6], valid=[True, False] * 3, datalist=True),
        },
        "height_gwy": {
            "field_4x3.gwy": gwy(4, 3, wave),
            "masked_2x2.gwy": gwy(2, 2, wave[:4], mask=[0, 1, 0, 0]),
        },
        "height_gsf": {
            "field_4x3.gsf": gsf(4, 3, [v * 1e6 for v in wave]),
            "profile_5x1.gsf": gsf(5, 1, [1, 2, float("nan"), 4, 5]),
        },
    }
    for target, files in seeds.items():
        folder = ROOT / target
        folder.mkdir(parents=True, exist_ok=True)
        for name, payload in files.items():
            (folder / name).write_bytes(payload)


if __name__ == "__main__":
    main()
