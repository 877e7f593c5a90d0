// The x3p writer (ISO 25178-72 / ISO 5436-2): main.xml (tinyxml2), the binary point data and
// md5checksum.hex in a zip archive written in memory by libzip, with reproducible bytes.
// Conventions and units: docs/height-files.md, section "x3p"; the reader is format_x3p.cpp.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <tinyxml2.h>
#include <zip.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "x3p_text.hpp"

namespace roughscope::surface::formats {

namespace {

using x3p::md5_hex;
using x3p::um_to_metres_text;

struct ZipSourceFree {
    void operator()(zip_source_t* s) const { zip_source_free(s); }
};

class ZipWriter {
  public:
    ZipWriter() {
        zip_error_t error;
        zip_error_init(&error);
        source_.reset(zip_source_buffer_create(nullptr, 0, 0, &error));
        if (!source_) throw Error("x3p: libzip cannot create an archive in memory");
        zip_source_keep(source_.get());
        archive_ = zip_open_from_source(source_.get(), ZIP_TRUNCATE, &error);
        zip_error_fini(&error);
        if (!archive_) throw Error("x3p: libzip cannot create an archive in memory");
    }
    ~ZipWriter() {
        if (archive_) zip_discard(archive_);
    }
    ZipWriter(const ZipWriter&) = delete;
    ZipWriter& operator=(const ZipWriter&) = delete;

    // `data` must live until finish().
    void add(const char* entry, std::string_view data, bool compress) {
        zip_source_t* s = zip_source_buffer(archive_, data.data(), data.size(), 0);
        if (!s) throw Error("x3p: libzip cannot add an entry");
        const zip_int64_t index = zip_file_add(archive_, entry, s, ZIP_FL_ENC_UTF_8);
        if (index < 0) {
            zip_source_free(s);
            throw Error("x3p: libzip cannot add an entry");
        }
        const auto i = static_cast<zip_uint64_t>(index);
        zip_set_file_compression(archive_, i, compress ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0);
        zip_file_set_mtime(archive_, i, 315532800, 0);  // 1980-01-01: reproducible bytes
    }

    std::string finish() {
        if (zip_close(archive_) != 0) throw Error("x3p: libzip cannot write the archive");
        archive_ = nullptr;
        zip_source_t* s = source_.get();
        zip_stat_t st;
        zip_stat_init(&st);
        if (zip_source_stat(s, &st) != 0 || zip_source_open(s) != 0) {
            throw Error("x3p: libzip cannot read the archive back");
        }
        std::string out(static_cast<std::size_t>(st.size), '\0');
        const zip_int64_t got = zip_source_read(s, out.data(), out.size());
        zip_source_close(s);
        if (got != static_cast<zip_int64_t>(out.size())) {
            throw Error("x3p: libzip cannot read the archive back");
        }
        return out;
    }

  private:
    std::unique_ptr<zip_source_t, ZipSourceFree> source_;
    zip_t* archive_ = nullptr;
};

void element(tinyxml2::XMLPrinter& p, const char* tag, const std::string& text) {
    p.OpenElement(tag, true);
    p.PushText(text.c_str());
    p.CloseElement(true);
}

void write_axis(tinyxml2::XMLPrinter& p, const char* tag, const char* axis_type,
                const char* data_type, const std::string& increment, const std::string& offset) {
    p.OpenElement(tag);
    element(p, "AxisType", axis_type);
    element(p, "DataType", data_type);
    element(p, "Increment", increment);
    element(p, "Offset", offset);
    p.CloseElement();
}

}  // namespace

std::string encode_x3p(const HeightMap& map, const HeightWriteOptions&) {
    validate(map, "x3p output");
    const std::size_t n = map.size();
    const bool missing = map.has_missing();

    // Heights in µm as float64 with CZ Increment 1e-6 m: physical metres = 1e-6 × value, read
    // back bit for bit (the reader skips a factor of exactly 1 µm).
    std::string data(n * sizeof(double), '\0');
    std::memcpy(data.data(), map.heights_um.data(), data.size());
    std::string valid;
    if (missing) {
        valid.assign((n + 7) / 8, '\0');
        for (std::size_t i = 0; i < n; ++i) {
            if (!std::isnan(map.heights_um[i])) {
                valid[i / 8] =
                    static_cast<char>(static_cast<unsigned char>(valid[i / 8]) | (1U << (i % 8)));
            }
        }
    }

    tinyxml2::XMLPrinter p(nullptr, false, 0);
    p.PushHeader(false, true);
    p.OpenElement("p:ISO5436_2");
    p.PushAttribute("xmlns:p", "http://www.opengps.eu/2008/ISO5436_2");
    p.PushAttribute("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance");
    p.PushAttribute("xsi:schemaLocation",
                    "http://www.opengps.eu/2008/ISO5436_2 "
                    "http://www.opengps.eu/2008/ISO5436_2/ISO5436_2.xsd");
    p.OpenElement("Record1");
    element(p, "Revision", "ISO5436 - 2000");
    element(p, "FeatureType", map.is_profile() ? "PRF" : "SUR");
    p.OpenElement("Axes");
    write_axis(p, "CX", "I", "D", um_to_metres_text(map.dx_um), um_to_metres_text(map.x_offset_um));
    write_axis(p, "CY", "I", "D", um_to_metres_text(map.dy_um), um_to_metres_text(map.y_offset_um));
    write_axis(p, "CZ", "A", "D", "1e-6", "0");
    p.CloseElement();  // Axes
    p.CloseElement();  // Record1
    if (!map.title.empty()) {
        p.OpenElement("Record2");
        element(p, "Date", "1970-01-01T00:00:00");
        p.OpenElement("Instrument");
        element(p, "Manufacturer", "unknown");
        element(p, "Model", "unknown");
        element(p, "Serial", "unknown");
        element(p, "Version", "unknown");
        p.CloseElement();
        element(p, "CalibrationDate", "1970-01-01T00:00:00");
        p.OpenElement("ProbingSystem");
        element(p, "Type", "Software");
        element(p, "Identification", "roughscope");
        p.CloseElement();
        element(p, "Comment", map.title);
        p.CloseElement();
    }
    p.OpenElement("Record3");
    p.OpenElement("MatrixDimension");
    element(p, "SizeX", std::to_string(map.nx));
    element(p, "SizeY", std::to_string(map.ny));
    element(p, "SizeZ", "1");
    p.CloseElement();
    p.OpenElement("DataLink");
    element(p, "PointDataLink", "bindata/data.bin");
    element(p, "MD5ChecksumPointData", md5_hex(data));
    if (missing) {
        element(p, "ValidPointsLink", "bindata/valid.bin");
        element(p, "MD5ChecksumValidPoints", md5_hex(valid));
    }
    p.CloseElement();  // DataLink
    p.CloseElement();  // Record3
    p.OpenElement("Record4");
    element(p, "ChecksumFile", "md5checksum.hex");
    p.CloseElement();
    p.CloseElement();  // root
    const std::string xml(p.CStr(), static_cast<std::size_t>(p.CStrSize() - 1));
    const std::string checksum = md5_hex(xml) + " *main.xml\n";

    ZipWriter zip;
    zip.add("main.xml", xml, true);
    zip.add("md5checksum.hex", checksum, false);
    // Doubles barely compress: stored, reading them back is one checksum pass.
    zip.add("bindata/data.bin", data, false);
    if (missing) zip.add("bindata/valid.bin", valid, true);
    return zip.finish();
}

}  // namespace roughscope::surface::formats
