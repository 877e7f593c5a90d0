// x3p reader and writer (formats.hpp, docs/height-files.md "x3p"): bit-exact round trips, files
// built here from the ISO 5436-2 layout with plain libzip calls and an XML string typed from the
// specification (not the project's writer), malformed input, and the real files of
// ../shared/data/heights.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <openssl/evp.h>
#include <zip.h>

#include "../io/shared_data.hpp"
#include "../io/test_files.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string md5(const std::string& data) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    EVP_Digest(data.data(), data.size(), digest, &n, EVP_md5(), nullptr);
    std::string out;
    char hex[3];
    for (unsigned int i = 0; i < n; ++i) {
        std::snprintf(hex, sizeof hex, "%02x", digest[i]);
        out += hex;
    }
    return out;
}

// An independent minimal zip writer: plain libzip calls, entries in the order given (deflated,
// or stored when `stored`).
std::string make_zip(const std::vector<std::pair<std::string, std::string>>& entries,
                     bool stored = false) {
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
    zip_source_keep(buffer);
    zip_t* z = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
    for (const auto& [entry, data] : entries) {
        zip_source_t* s = zip_source_buffer(z, data.data(), data.size(), 0);
        const zip_int64_t index = zip_file_add(z, entry.c_str(), s, 0);
        if (stored) zip_set_file_compression(z, static_cast<zip_uint64_t>(index), ZIP_CM_STORE, 0);
    }
    zip_close(z);
    zip_stat_t st;
    zip_source_stat(buffer, &st);
    zip_source_open(buffer);
    std::string out(st.size, '\0');
    zip_source_read(buffer, out.data(), out.size());
    zip_source_close(buffer);
    zip_source_free(buffer);
    zip_error_fini(&error);
    return out;
}

// main.xml typed from ISO 5436-2: 3 x 2 float32 Z in metres, CX 0.5 um, CY 0.25 um, the data in
// bindata/data.bin; `data_md5` goes into MD5ChecksumPointData.
std::string spec_main_xml(const std::string& data_md5, const std::string& size_x = "3",
                          const std::string& increment_x = "5.0E-7") {
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<p:ISO5436_2 xmlns:p=\"http://www.opengps.eu/2008/ISO5436_2\">\n"
           "<Record1><Revision>ISO5436 - 2000</Revision><FeatureType>SUR</FeatureType>\n"
           "<Axes><CX><AxisType>I</AxisType><DataType>D</DataType><Increment>" +
           increment_x +
           "</Increment><Offset>1.0E-6</Offset></CX>\n"
           "<CY><AxisType>I</AxisType><DataType>D</DataType><Increment>2.5E-7</Increment>"
           "<Offset>0</Offset></CY>\n"
           "<CZ><AxisType>A</AxisType><DataType>F</DataType></CZ></Axes></Record1>\n"
           "<Record3><MatrixDimension><SizeX>" +
           size_x +
           "</SizeX><SizeY>2</SizeY><SizeZ>1</SizeZ></MatrixDimension>\n"
           "<DataLink><PointDataLink>bindata/data.bin</PointDataLink>"
           "<MD5ChecksumPointData>" +
           data_md5 +
           "</MD5ChecksumPointData></DataLink></Record3>\n"
           "<Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4></p:ISO5436_2>\n";
}

// Z = 1, 2, -3 um; 4 um, +inf (missing), 0.5 um, as float32 metres.
std::string spec_data() {
    const float z[6] = {1e-6F, 2e-6F, -3e-6F, 4e-6F, std::numeric_limits<float>::infinity(), 5e-7F};
    return std::string(reinterpret_cast<const char*>(z), sizeof z);
}

std::string spec_x3p(const std::string& xml, const std::string& data,
                     const std::string& folder = "") {
    return make_zip({{folder + "main.xml", xml},
                     {folder + "md5checksum.hex", md5(xml) + " *main.xml\n"},
                     {folder + "bindata/data.bin", data}});
}

HeightMap sample_map(std::size_t nx, std::size_t ny) {
    HeightMap map = make_height_map(nx, ny, 0.1, 1.0 / 3.0);
    map.x_offset_um = -12.345678901234567;
    map.y_offset_um = 1e-7;
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] =
            std::sin(0.37 * static_cast<double>(i)) * 1.2345e-3 + 1e-9 * static_cast<double>(i);
    }
    if (map.size() > 1) map.heights_um[1] = -0.0;
    return map;
}

std::string decode_error(const std::string& bytes, const HeightReadOptions& options = {}) {
    try {
        (void)formats::decode_x3p(bytes, "bad.x3p", options);
    } catch (const DataError& e) {
        return e.what();
    }
    return "no DataError";
}

TEST(X3pFormat, IndependentlyWrittenFileReadsAsIntended) {
    const std::string data = spec_data();
    const HeightMap map =
        formats::decode_x3p(spec_x3p(spec_main_xml(md5(data)), data), "spec.x3p", {});
    ASSERT_EQ(map.nx, 3U);
    ASSERT_EQ(map.ny, 2U);
    EXPECT_EQ(map.dx_um, 0.5);  // "5.0E-7" m is exactly 0.5 um
    EXPECT_EQ(map.dy_um, 0.25);
    EXPECT_EQ(map.x_offset_um, 1.0);
    EXPECT_EQ(map.y_offset_um, 0.0);
    // float32 metres: 1e-6F is 1 um to float32 precision.
    EXPECT_NEAR(map.at(0, 0), 1.0, 1e-6);
    EXPECT_NEAR(map.at(2, 0), -3.0, 1e-6);
    EXPECT_NEAR(map.at(0, 1), 4.0, 1e-6);
    EXPECT_TRUE(std::isnan(map.at(1, 1)));  // +inf in the file = missing
    EXPECT_NEAR(map.at(2, 1), 0.5, 1e-7);
    EXPECT_EQ(map.count_valid(), 5U);
}

// Doubles in µm (CZ Increment 1e-6 m) are checked against the height rule of validate chunk by
// chunk as they are read: a height beyond ±1e30 µm past the first chunk of 65536 points is named,
// ±inf is a missing point, a file of missing points only is refused; checksums verified or not.
TEST(X3pFormat, DoubleHeightsAreCheckedAsTheyAreRead) {
    constexpr std::size_t kSide = 300;  // 90000 points: two chunks
    std::string xml = spec_main_xml("", std::to_string(kSide));
    const std::string float_z = "<CZ><AxisType>A</AxisType><DataType>F</DataType></CZ>";
    const std::string double_z =
        "<CZ><AxisType>A</AxisType><DataType>D</DataType><Increment>1.0E-6</Increment>"
        "<Offset>0</Offset></CZ>";
    xml.replace(xml.find(float_z), float_z.size(), double_z);
    xml.replace(xml.find("<SizeY>2</SizeY>"), 16, "<SizeY>" + std::to_string(kSide) + "</SizeY>");
    const auto file_of = [&](const std::vector<double>& z) {
        const std::string data(reinterpret_cast<const char*>(z.data()), z.size() * sizeof(double));
        std::string with_md5 = xml;
        with_md5.replace(with_md5.find("<MD5ChecksumPointData></MD5ChecksumPointData>"),
                         std::string("<MD5ChecksumPointData></MD5ChecksumPointData>").size(),
                         "<MD5ChecksumPointData>" + md5(data) + "</MD5ChecksumPointData>");
        return spec_x3p(with_md5, data);
    };
    std::vector<double> z(kSide * kSide, 0.25);
    z[10] = -std::numeric_limits<double>::infinity();
    HeightReadOptions unverified;
    unverified.x3p_verify_checksums = false;
    for (const HeightReadOptions& options : {HeightReadOptions{}, unverified}) {
        const HeightMap map = formats::decode_x3p(file_of(z), "good.x3p", options);
        EXPECT_EQ(map.count_valid(), z.size() - 1);
        EXPECT_TRUE(std::isnan(map.heights_um[10]));
        EXPECT_EQ(map.heights_um[70000], 0.25);
        std::vector<double> far = z;
        far[70000] = 5e30;
        far[80000] = -7e30;
        const std::string error = decode_error(file_of(far), options);
        EXPECT_NE(error.find("bad.x3p"), std::string::npos) << error;
        EXPECT_NE(error.find("got 5e+30"), std::string::npos) << error;
        const std::vector<double> missing(z.size(), kNaN);
        EXPECT_NE(decode_error(file_of(missing), options).find("every point is missing"),
                  std::string::npos);
    }
}

TEST(X3pFormat, NestedFolderAndOsMetadataEntriesAreIgnored) {
    const std::string data = spec_data();
    const std::string xml = spec_main_xml(md5(data));
    const std::string zip = make_zip({{"__MACOSX/._top", "junk"},
                                      {"top/main.xml", xml},
                                      {"top/md5checksum.hex", md5(xml)},
                                      {"top/bindata/.DS_Store", "junk"},
                                      {"__MACOSX/top/main.xml", "not xml"},
                                      {"top/bindata/data.bin", data}});
    const HeightMap map = formats::decode_x3p(zip, "nested.x3p", {});
    EXPECT_EQ(map.nx, 3U);
    EXPECT_EQ(map.count_valid(), 5U);
    // Without the stray entries being skipped, "__MACOSX/top/main.xml" would be a second main.xml.
    EXPECT_EQ(
        decode_error(make_zip({{"a/main.xml", xml}, {"b/main.xml", xml}})).find("more than one") !=
            std::string::npos,
        true);
}

TEST(X3pFormat, RoundTripIsBitExact) {
    for (const auto& [nx, ny] : {std::pair<std::size_t, std::size_t>{7, 5}, {9, 1}, {1, 1}}) {
        HeightMap map = sample_map(nx, ny);
        map.title = "a <title> & \"quotes\"";
        const std::string bytes = formats::encode_x3p(map, {});
        const HeightMap back = formats::decode_x3p(bytes, "round.x3p", {});
        EXPECT_TRUE(bitwise_equal(map, back)) << nx << " x " << ny;
        EXPECT_EQ(back.title, map.title);
    }
    // Awkward spacings and offsets: values whose metres × 1e6 would not come back.
    HeightMap map = sample_map(4, 3);
    for (double d : {0.1, 3.679e0, 1e-29, 7.000000000000001, 123456.789e10, 0.3}) {
        map.dx_um = d;
        map.dy_um = d * 3;
        map.x_offset_um = -d;
        map.y_offset_um = 5e-324;
        const HeightMap back = formats::decode_x3p(formats::encode_x3p(map, {}), "round.x3p", {});
        EXPECT_TRUE(bitwise_equal(map, back)) << d;
    }
}

TEST(X3pFormat, RoundTripKeepsMissingPointsThroughTheValidityBitmap) {
    HeightMap map = sample_map(11, 3);
    map.heights_um[0] = kNaN;
    map.heights_um[9] = kNaN;
    map.heights_um[32] = kNaN;
    const std::string bytes = formats::encode_x3p(map, {});
    const HeightMap back = formats::decode_x3p(bytes, "holes.x3p", {});
    EXPECT_TRUE(bitwise_equal(map, back));
    EXPECT_EQ(back.count_valid(), 30U);
    // The bitmap, not only the NaNs in data.bin, marks them: an independent read of valid.bin.
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* src = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
    zip_t* z = zip_open_from_source(src, ZIP_RDONLY, &error);
    ASSERT_NE(z, nullptr);
    zip_file_t* f = zip_fopen(z, "bindata/valid.bin", 0);
    ASSERT_NE(f, nullptr);
    unsigned char bits[5] = {};
    EXPECT_EQ(zip_fread(f, bits, sizeof bits), 5);
    zip_fclose(f);
    zip_discard(z);
    EXPECT_EQ(bits[0], 0xFE);  // point 0 invalid, least significant bit first
    EXPECT_EQ(bits[1], 0xFD);  // point 9
    EXPECT_EQ(bits[4], 0x00);  // point 32 invalid, bits past the end zero
}

TEST(X3pFormat, ProfileIsWrittenAsPrf) {
    const HeightMap map = sample_map(16, 1);
    const std::string bytes = formats::encode_x3p(map, {});
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* src = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
    zip_t* z = zip_open_from_source(src, ZIP_RDONLY, &error);
    ASSERT_NE(z, nullptr);
    zip_stat_t st;
    ASSERT_EQ(zip_stat(z, "main.xml", 0, &st), 0);
    std::string xml(st.size, '\0');
    zip_file_t* f = zip_fopen(z, "main.xml", 0);
    zip_fread(f, xml.data(), xml.size());
    zip_fclose(f);
    EXPECT_EQ(zip_name_locate(z, "bindata/valid.bin", 0), -1);  // nothing missing: no bitmap
    zip_discard(z);
    EXPECT_NE(xml.find("<FeatureType>PRF</FeatureType>"), std::string::npos);
    EXPECT_NE(xml.find("<MD5ChecksumPointData>"), std::string::npos);
}

TEST(X3pFormat, EncodeRejectsAnInvalidMap) {
    HeightMap map = sample_map(3, 3);
    map.heights_um.pop_back();
    EXPECT_THROW((void)formats::encode_x3p(map, {}), InvalidArgument);
    HeightMap all_missing = sample_map(2, 2);
    for (double& z : all_missing.heights_um) z = kNaN;
    EXPECT_THROW((void)formats::encode_x3p(all_missing, {}), InvalidArgument);
}

TEST(X3pFormat, ChecksumMismatchesAreDataErrors) {
    const std::string data = spec_data();
    // Point data: MD5 in main.xml does not match data.bin.
    std::string message = decode_error(spec_x3p(spec_main_xml(std::string(32, '0')), data));
    EXPECT_NE(message.find("bad.x3p"), std::string::npos) << message;
    EXPECT_NE(message.find("MD5ChecksumPointData"), std::string::npos) << message;
    // main.xml: md5checksum.hex does not match.
    const std::string xml = spec_main_xml(md5(data));
    message = decode_error(make_zip({{"main.xml", xml},
                                     {"md5checksum.hex", std::string(32, 'a') + " *main.xml\n"},
                                     {"bindata/data.bin", data}}));
    EXPECT_NE(message.find("md5checksum.hex"), std::string::npos) << message;
    EXPECT_NE(message.find("main.xml"), std::string::npos) << message;
    // A malformed stated checksum.
    message = decode_error(spec_x3p(spec_main_xml("xyz"), data));
    EXPECT_NE(message.find("32 hex digits"), std::string::npos) << message;
    // Verification off: the stale file reads.
    HeightReadOptions lax;
    lax.x3p_verify_checksums = false;
    EXPECT_EQ(formats::decode_x3p(spec_x3p(spec_main_xml(std::string(32, '0')), data), "x", lax).nx,
              3U);
}

// A stored data.bin edited in place (its zip CRC-32 and its MD5 both stale): a verified read is a
// DataError; a read that does not verify checksums takes the edited values, in each chunk of
// 65536 points at its place (it reads the stored member in windows of the archive).
TEST(X3pFormat, UnverifiedReadTakesAStoredMemberWithAStaleCrc) {
    const HeightMap map = sample_map(300, 300);  // 90000 points: two chunks
    std::string bytes = formats::encode_x3p(map, {});
    for (const std::size_t point : {std::size_t{5}, std::size_t{70000}}) {
        const std::string old_bits(reinterpret_cast<const char*>(&map.heights_um[point]), 8);
        const std::size_t at = bytes.find(old_bits);
        ASSERT_NE(at, std::string::npos);
        ASSERT_EQ(bytes.find(old_bits, at + 1), std::string::npos);  // the point, nothing else
        const double edited = 42.0 + static_cast<double>(point);
        bytes.replace(at, 8, reinterpret_cast<const char*>(&edited), 8);
    }
    EXPECT_NE(decode_error(bytes), "no DataError");
    HeightReadOptions lax;
    lax.x3p_verify_checksums = false;
    const HeightMap back = formats::decode_x3p(bytes, "edited.x3p", lax);
    EXPECT_EQ(back.heights_um[5], 47.0);
    EXPECT_EQ(back.heights_um[70000], 70042.0);
    EXPECT_EQ(back.heights_um[4], map.heights_um[4]);
    EXPECT_EQ(back.heights_um[89999], map.heights_um[89999]);
}

// The zip's CRC-32 is a checksum too: a stored data.bin edited in place in a file that states no
// MD5 is a DataError naming the member when checksums are verified, and reads without.
TEST(X3pFormat, VerifiedReadChecksTheZipCrcOfThePointData) {
    const std::string xml = spec_main_xml("");
    std::string bytes = make_zip({{"main.xml", xml},
                                  {"md5checksum.hex", md5(xml) + " *main.xml\n"},
                                  {"bindata/data.bin", spec_data()}},
                                 /*stored=*/true);
    const float old_z = 4e-6F, new_z = 8e-6F;
    const std::size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&old_z), 4));
    ASSERT_NE(at, std::string::npos);
    bytes.replace(at, 4, reinterpret_cast<const char*>(&new_z), 4);
    const std::string message = decode_error(bytes);
    EXPECT_NE(message.find("bad.x3p"), std::string::npos) << message;
    EXPECT_NE(message.find("bindata/data.bin"), std::string::npos) << message;
    EXPECT_NE(message.find("CRC"), std::string::npos) << message;
    HeightReadOptions lax;
    lax.x3p_verify_checksums = false;
    EXPECT_NEAR(formats::decode_x3p(bytes, "x", lax).at(0, 1), 8.0, 1e-6);
}

TEST(X3pFormat, AbsentChecksumsAreAccepted) {
    const std::string data = spec_data();
    const std::string xml = spec_main_xml("");
    const HeightMap map =
        formats::decode_x3p(make_zip({{"main.xml", xml}, {"bindata/data.bin", data}}), "x", {});
    EXPECT_EQ(map.count_valid(), 5U);
}

TEST(X3pFormat, MalformedInputIsADataErrorNamingTheFile) {
    const std::string data = spec_data();
    const std::string good = spec_x3p(spec_main_xml(md5(data)), data);
    auto expect = [](const std::string& bytes, const std::string& fragment) {
        const std::string message = decode_error(bytes);
        EXPECT_NE(message.find("bad.x3p"), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    };
    expect(good.substr(0, good.size() / 2), "zip");
    expect("", "zip");
    expect(make_zip({{"bindata/data.bin", data}}), "no main.xml");
    expect(spec_x3p(spec_main_xml(md5(data), "4"), data), "bytes");  // larger than the data
    expect(spec_x3p(spec_main_xml(md5(data), "99999999999"), data), "MatrixDimension");
    expect(spec_x3p(spec_main_xml(md5(data), "3", "1.5e-6x"), data), "not a number");
    expect(spec_x3p(spec_main_xml(md5(data), "3", "1e999999"), data), "not a number");
    expect(spec_x3p(spec_main_xml(md5(data), "-3"), data), "not a count");
    expect(spec_x3p("<p:ISO5436_2><Record1>", data), "well-formed");
    std::string pcl = spec_main_xml(md5(data));
    pcl.replace(pcl.find("SUR"), 3, "PCL");
    expect(spec_x3p(pcl, data), "point clouds are not supported");
    expect(make_zip({{"main.xml", spec_main_xml(md5(data))}}), "absent from the zip");
}

TEST(X3pFormat, DataListWithEmptyDatumAndIntegerCoding) {
    const std::string xml =
        "<ISO5436_2><Record1><FeatureType>SUR</FeatureType><Axes>"
        "<CX><AxisType>I</AxisType><Increment>1e-6</Increment></CX>"
        "<CY><AxisType>I</AxisType><Increment>2e-6</Increment></CY>"
        "<CZ><AxisType>A</AxisType><DataType>L</DataType><Increment>1e-9</Increment>"
        "<Offset>-1e-6</Offset></CZ></Axes></Record1>"
        "<Record3><MatrixDimension><SizeX>2</SizeX><SizeY>2</SizeY><SizeZ>1</SizeZ>"
        "</MatrixDimension><DataList><Datum>1000</Datum><Datum/><Datum>-500</Datum>"
        "<Datum>0</Datum></DataList></Record3></ISO5436_2>";
    const HeightMap map = formats::decode_x3p(make_zip({{"main.xml", xml}}), "list.x3p", {});
    EXPECT_EQ(map.dy_um, 2.0);
    EXPECT_DOUBLE_EQ(map.at(0, 0), 0.0);  // -1 um + 1000 nm
    EXPECT_TRUE(std::isnan(map.at(1, 0)));
    EXPECT_DOUBLE_EQ(map.at(0, 1), -1.5);
    EXPECT_DOUBLE_EQ(map.at(1, 1), -1.0);
    std::string short_list = xml;
    short_list.replace(short_list.find("<Datum>0</Datum>"), 16, "");
    EXPECT_NE(decode_error(make_zip({{"main.xml", short_list}})).find("3 <Datum>"),
              std::string::npos);
}

// ---- real files ------------------------------------------------------------------------------

std::optional<std::filesystem::path> heights_dir() {
    const auto file =
        io::find_shared("data/heights/sample-land.x3p", testing::shared_search_starts());
    if (!file) return std::nullopt;
    return file->parent_path();
}

HeightMap read_real(const std::filesystem::path& dir, const char* file,
                    const HeightReadOptions& options = {}) {
    return read_height_map(dir / file, options);
}

TEST(X3pFormat, RealInfiniteFocusFilesWithInfinities) {
    const auto dir = heights_dir();
    ROUGHSCOPE_NEED_SHARED(dir, "data/heights");
    const HeightMap ski = read_real(*dir, "SkiInfiniteFocus.x3p");
    EXPECT_EQ(ski.nx, 1197U);
    EXPECT_EQ(ski.ny, 940U);
    EXPECT_NEAR(ski.dx_um, 3.679, 5e-4);
    EXPECT_NEAR(ski.dy_um, 3.680, 5e-4);
    EXPECT_EQ(ski.size() - ski.count_valid(), 4272U);
    const HeightMap rubber = read_real(*dir, "KautschukInfiniteFocus.x3p");
    EXPECT_EQ(rubber.nx, 860U);
    EXPECT_EQ(rubber.ny, 634U);
    EXPECT_NEAR(rubber.dx_um, 2.280, 5e-4);
    EXPECT_EQ(rubber.size() - rubber.count_valid(), 5296U);
    // Heights in µm: the ski's float32 metres span tens of µm.
    double lo = 1e300;
    double hi = -1e300;
    for (double z : ski.heights_um) {
        if (!std::isnan(z)) lo = std::min(lo, z), hi = std::max(hi, z);
    }
    EXPECT_NEAR(lo, -51.93, 0.01);
    EXPECT_NEAR(hi, 32.31, 0.01);
}

TEST(X3pFormat, RealNestedFileWithNaNsAndMacMetadata) {
    const auto dir = heights_dir();
    ROUGHSCOPE_NEED_SHARED(dir, "data/heights");
    const HeightMap land = read_real(*dir, "sample-land.x3p");
    EXPECT_EQ(land.nx, 918U);
    EXPECT_EQ(land.ny, 256U);
    EXPECT_EQ(land.dx_um, 2.58);  // "2.58e-06" m, exactly
    EXPECT_EQ(land.dy_um, 2.58);
    EXPECT_EQ(land.size() - land.count_valid(), 25292U);
    // Re-encoded and read back: identical.
    EXPECT_TRUE(bitwise_equal(land, formats::decode_x3p(formats::encode_x3p(land, {}), "re", {})));
}

TEST(X3pFormat, RealOpenGpsSamples) {
    const auto dir = heights_dir();
    ROUGHSCOPE_NEED_SHARED(dir, "data/heights");
    const HeightMap list = read_real(*dir, "ISO5436-sample1.x3p");
    const HeightMap bin = read_real(*dir, "ISO5436-sample1_bin.x3p");
    for (const HeightMap* m : {&list, &bin}) {
        EXPECT_EQ(m->nx, 4U);
        EXPECT_EQ(m->ny, 4U);
        EXPECT_EQ(m->dx_um, 16016.0);
        EXPECT_EQ(m->count_valid(), 15U);
        EXPECT_TRUE(std::isnan(m->at(3, 1)));
        EXPECT_DOUBLE_EQ(m->at(0, 0), 4.86219120804151e5);  // 0.486 m in µm
    }
    const HeightMap int_list = read_real(*dir, "ISO5436-sample4.x3p");
    const HeightMap int_bin = read_real(*dir, "ISO5436-sample4_bin.x3p");
    EXPECT_EQ(int_list.count_valid(), int_bin.count_valid());
    for (std::size_t i = 0; i < int_list.size(); ++i) {
        if (std::isnan(int_list.heights_um[i])) continue;
        EXPECT_DOUBLE_EQ(int_list.heights_um[i], int_bin.heights_um[i]) << i;
        // physical = -0.5 m + 0.001 m × count: whole mm steps around -0.5 m.
        const double counts = (int_list.heights_um[i] + 5e5) / 1e3;
        EXPECT_NEAR(counts, std::round(counts), 1e-6) << i;
    }
    const HeightMap absolute_y = read_real(*dir, "ISO5436-sample3.x3p");
    EXPECT_EQ(absolute_y.dy_um, 2e6);        // integer-coded Y, increment 2.0 m
    EXPECT_EQ(absolute_y.y_offset_um, 3e6);  // 1 m + 2 m × the first count (1)
    EXPECT_EQ(absolute_y.x_offset_um, 1e5);
    EXPECT_EQ(absolute_y.count_valid(), 15U);
    try {
        (void)read_real(*dir, "ISO5436-sample2.x3p");
        ADD_FAILURE() << "a point cloud was read";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("point clouds are not supported"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("ISO5436-sample2.x3p"), std::string::npos);
    }
}

TEST(X3pFormat, RealFileWithAStaleMainXmlChecksum) {
    const auto dir = heights_dir();
    ROUGHSCOPE_NEED_SHARED(dir, "data/heights");
    // csafe-logo.x3p's md5checksum.hex does not match its main.xml (edited after writing).
    try {
        (void)read_real(*dir, "csafe-logo.x3p");
        ADD_FAILURE() << "a stale checksum was accepted";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("md5checksum.hex"), std::string::npos) << e.what();
    }
    HeightReadOptions lax;
    lax.x3p_verify_checksums = false;
    const HeightMap logo = read_real(*dir, "csafe-logo.x3p", lax);
    EXPECT_EQ(logo.nx, 741U);
    EXPECT_EQ(logo.ny, 419U);
    EXPECT_EQ(logo.dy_um, 0.645);
    EXPECT_EQ(logo.count_valid(), logo.size());
}

}  // namespace
}  // namespace roughscope::surface

namespace roughscope::surface {
namespace {

// The fuzz seeds come from fuzz/make_height_seeds_x3p.py, a second independent writer (Python's
// zipfile, hashlib and struct): each must read as a valid map.
TEST(HeightSeedFiles, EverySeedReads) {
    const std::filesystem::path corpus =
        std::filesystem::path(ROUGHSCOPE_SOURCE_DIR) / "fuzz" / "corpus";
    std::size_t files = 0;
    for (const auto& [target, format] : {std::pair{"height_x3p", HeightFormat::X3p},
                                         {"height_gwy", HeightFormat::Gwy},
                                         {"height_gsf", HeightFormat::Gsf}}) {
        for (const auto& entry : std::filesystem::directory_iterator(corpus / target)) {
            const std::string bytes = testing::slurp(entry.path());
            const HeightMap map =
                decode_height_map(bytes, entry.path().filename().string(), format);
            EXPECT_GE(map.count_valid(), 1U) << entry.path();
            ++files;
        }
    }
    EXPECT_GE(files, 9U);
}

}  // namespace
}  // namespace roughscope::surface
