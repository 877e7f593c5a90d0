// Gwyddion .gwy reader and .gsf reader/writer (formats.hpp, docs/height-files.md "Gwyddion .gwy
// and .gsf"): files built byte by byte here from the format descriptions in the Gwyddion user
// guide (not the project's writer), round trips, malformed input and the real gwyfile-test.gwy.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../io/shared_data.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::surface {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <class T>
std::string le(T v) {
    std::string s(sizeof v, '\0');
    std::memcpy(s.data(), &v, sizeof v);
    return s;
}
std::string cstr(const std::string& s) { return s + std::string(1, '\0'); }

// ---- an independent GWY writer: objects, components, arrays as the user guide lays them out ----

std::string gwy_object(const std::string& type, const std::string& components) {
    return cstr(type) + le<std::uint32_t>(static_cast<std::uint32_t>(components.size())) +
           components;
}
std::string comp_int(const std::string& key, std::int32_t v) { return cstr(key) + "i" + le(v); }
std::string comp_double(const std::string& key, double v) { return cstr(key) + "d" + le(v); }
std::string comp_string(const std::string& key, const std::string& v) {
    return cstr(key) + "s" + cstr(v);
}
std::string comp_object(const std::string& key, const std::string& object) {
    return cstr(key) + "o" + object;
}
std::string comp_doubles(const std::string& key, const std::vector<double>& v) {
    std::string s = cstr(key) + "D" + le<std::uint32_t>(static_cast<std::uint32_t>(v.size()));
    for (double x : v) s += le(x);
    return s;
}
std::string si_unit(const std::string& unit) {
    return gwy_object("GwySIUnit", comp_string("unitstr", unit));
}
std::string data_field(int xres, int yres, double xreal, double yreal, const std::string& unit_xy,
                       const std::string& unit_z, const std::vector<double>& data) {
    return gwy_object("GwyDataField",
                      comp_int("xres", xres) + comp_int("yres", yres) +
                          comp_double("xreal", xreal) + comp_double("yreal", yreal) +
                          comp_double("xoff", 2e-6) + comp_object("si_unit_xy", si_unit(unit_xy)) +
                          comp_object("si_unit_z", si_unit(unit_z)) + comp_doubles("data", data));
}

// A container with a voltage channel /0 (skipped), a height channel /3 in metres with a mask, and
// unrelated items (a boolean, an int64, a string array).
std::string spec_gwy() {
    const std::string volts = data_field(2, 1, 1.0, 1.0, "m", "V", {1.0, 2.0});
    const std::string heights =
        data_field(3, 2, 3e-6, 1e-6, "m", "m", {1e-6, 2e-6, 3e-6, -1e-6, 5e-7, 0.0});
    const std::string mask = data_field(3, 2, 3e-6, 1e-6, "m", "", {0, 0, 1, 0, 0, 0});
    std::string items = cstr("/0/data/visible") + "b" + std::string(1, '\1');
    items += comp_object("/0/data", volts);
    items += cstr("/3/meta") + "q" + le<std::int64_t>(-5);
    items += cstr("/strings") + "S" + le<std::uint32_t>(2) + cstr("a") + cstr("bc");
    items += comp_object("/3/data", heights);
    items += comp_object("/3/mask", mask);
    items += comp_string("/3/data/title", "Topography");
    return "GWYP" + gwy_object("GwyContainer", items);
}

std::string gwy_error(const std::string& bytes) {
    try {
        (void)formats::decode_gwy(bytes, "bad.gwy", {});
    } catch (const DataError& e) {
        return e.what();
    }
    return "no DataError";
}

TEST(GwyFormat, IndependentlyWrittenFileReadsAsIntended) {
    const HeightMap map = formats::decode_gwy(spec_gwy(), "spec.gwy", {});
    ASSERT_EQ(map.nx, 3U);
    ASSERT_EQ(map.ny, 2U);
    EXPECT_DOUBLE_EQ(map.dx_um, 1.0);
    EXPECT_DOUBLE_EQ(map.dy_um, 0.5);
    EXPECT_DOUBLE_EQ(map.x_offset_um, 2.0);
    EXPECT_DOUBLE_EQ(map.at(0, 0), 1.0);
    EXPECT_DOUBLE_EQ(map.at(1, 0), 2.0);
    EXPECT_TRUE(std::isnan(map.at(2, 0)));  // masked
    EXPECT_DOUBLE_EQ(map.at(0, 1), -1.0);
    EXPECT_DOUBLE_EQ(map.at(1, 1), 0.5);
    EXPECT_EQ(map.title, "Topography");
}

TEST(GwyFormat, MalformedInputIsADataErrorNamingTheFileAndOffset) {
    const std::string good = spec_gwy();
    auto expect = [](const std::string& bytes, const std::string& fragment) {
        const std::string message = gwy_error(bytes);
        EXPECT_NE(message.find("bad.gwy"), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    };
    expect("GWYO", "GWYO");
    expect("PNG!", "GWYP");
    for (std::size_t cut : {std::size_t{4}, std::size_t{20}, good.size() / 2, good.size() - 1}) {
        expect(good.substr(0, cut), "byte");
    }
    // An array claiming 2^31 doubles: refused from the bytes present, nothing allocated.
    std::string huge = good;
    const std::size_t at = huge.find(cstr("data") + "D", huge.find("/3/data"));
    const std::uint32_t count = 0x80000000U;
    std::memcpy(huge.data() + at + 6, &count, 4);
    expect(huge, "runs past");
    // xres × yres larger than the data.
    expect("GWYP" + gwy_object("GwyContainer",
                               comp_object("/0/data", data_field(4, 4, 1, 1, "m", "m", {1, 2}))),
           "data holds 2 values");
    expect("GWYP" + gwy_object("GwyContainer", comp_int("/0/x", 1)), "no channel");
    // A key "/data" (no channel number) is not a channel (and must not be cut before its start).
    expect("GWYP" + gwy_object("GwyContainer",
                               comp_object("/data", data_field(1, 1, 1, 1, "m", "m", {1}))),
           "no channel");
    expect("GWYP" + gwy_object("GwyContainer",
                               comp_object("/0/data", data_field(1, 1, 1, 1, "m", "A", {1}))),
           "length units");
    expect("GWYP" + gwy_object("GwyContainer", cstr("/0/data") + "x"), "unknown component type");
    std::string deep = si_unit("m");
    for (int i = 0; i < 40; ++i) deep = gwy_object("GwyContainer", comp_object("x", deep));
    expect("GWYP" + deep, "nested too deep");
}

TEST(GwyFormat, RealGwyfileTest) {
    const auto file =
        io::find_shared("data/heights/gwyfile-test.gwy", testing::shared_search_starts());
    ROUGHSCOPE_NEED_SHARED(file, "data/heights/gwyfile-test.gwy");
    const HeightMap map = read_height_map(*file);
    EXPECT_EQ(map.nx, 128U);
    EXPECT_EQ(map.ny, 128U);
    EXPECT_EQ(map.title, "Test");
    // xreal = 128 with no unit: metres (1 m per point).
    EXPECT_EQ(map.dx_um, 1e6);
    EXPECT_EQ(map.count_valid(), map.size());
    double first = 0.0;
    std::memcpy(&first, "\x1f\x0b\x0a\x09\x16\x08\x4b\x3f", 8);  // the file's first double
    EXPECT_EQ(map.heights_um[0], first * 1e6);
}

// ---- GSF ----------------------------------------------------------------------------------------

// An independent GSF writer: magic line, "key = value" lines, 1-4 NULs to a multiple of 4, float32.
std::string spec_gsf(const std::string& header_lines, const std::vector<float>& data,
                     std::optional<std::size_t> nul_count = std::nullopt) {
    std::string s = "Gwyddion Simple Field 1.0\n" + header_lines;
    s.append(nul_count.value_or(4 - s.size() % 4), '\0');
    for (float v : data) s += le(v);
    return s;
}

std::string gsf_error(const std::string& bytes) {
    try {
        (void)formats::decode_gsf(bytes, "bad.gsf", {});
    } catch (const DataError& e) {
        return e.what();
    }
    return "no DataError";
}

TEST(GsfFormat, IndependentlyWrittenFileReadsAsIntended) {
    const std::string bytes = spec_gsf(
        "XRes = 2\nYRes = 3\nXReal = 4e-6\n  YReal=1.5e-6  \nXOffset = 1e-3\nXYUnits = m\n"
        "ZUnits = nm\nTitle = Spec test\nVendorKey = ignored\n",
        {1.0F, 2.0F, -3.5F, std::numeric_limits<float>::quiet_NaN(), 1000.0F, 0.25F});
    ASSERT_EQ(bytes.size() % 4, 0U);
    const HeightMap map = formats::decode_gsf(bytes, "spec.gsf", {});
    ASSERT_EQ(map.nx, 2U);
    ASSERT_EQ(map.ny, 3U);
    EXPECT_EQ(map.dx_um, 2.0);
    EXPECT_DOUBLE_EQ(map.dy_um, 0.5);
    EXPECT_EQ(map.x_offset_um, 1000.0);
    EXPECT_EQ(map.at(0, 0), 0.001);  // 1 nm
    EXPECT_EQ(map.at(0, 1), -0.0035);
    EXPECT_TRUE(std::isnan(map.at(1, 1)));
    EXPECT_EQ(map.at(0, 2), 1.0);
    EXPECT_EQ(map.title, "Spec test");
}

HeightMap float_map(std::size_t nx, std::size_t ny) {
    HeightMap map = make_height_map(nx, ny, 0.1, 1.0 / 3.0);
    map.x_offset_um = -12.345678901234567;
    map.y_offset_um = 7e-300;
    for (std::size_t i = 0; i < map.size(); ++i) {
        map.heights_um[i] =
            static_cast<double>(static_cast<float>(std::cos(0.3 * static_cast<double>(i)) * 17.0));
    }
    if (map.size() > 1) map.heights_um[1] = -0.0;
    return map;
}

TEST(GsfFormat, RoundTripIsBitExactForFloat32Values) {
    for (const auto& [nx, ny] : {std::pair<std::size_t, std::size_t>{7, 5}, {3, 1}, {1, 1}}) {
        HeightMap map = float_map(nx, ny);
        map.title = "title with\nnewline";
        if (map.size() > 2) map.heights_um[2] = kNaN;
        const HeightMap back = formats::decode_gsf(formats::encode_gsf(map, {}), "r.gsf", {});
        EXPECT_TRUE(bitwise_equal(map, back)) << nx << " x " << ny;
        EXPECT_EQ(back.title, "title with newline");
    }
    // Spacings whose n × d does not divide back to d are still exact.
    HeightMap map = float_map(3, 7);
    for (double d : {0.1, 1.0 / 3.0, 2.58, 3.678887926, 1e-5, 123.456, 0.7}) {
        for (std::size_t n : {3U, 7U, 11U, 1000U, 4097U}) {
            map = float_map(n, 2);
            map.dx_um = d;
            map.dy_um = d * 1.5;
            const HeightMap back = formats::decode_gsf(formats::encode_gsf(map, {}), "r.gsf", {});
            EXPECT_TRUE(bitwise_equal(map, back)) << d << " " << n;
        }
    }
}

TEST(GsfFormat, WriterRoundsToFloat32AndRejectsOutOfRange) {
    HeightMap map = float_map(2, 2);
    map.heights_um[0] = 0.1;  // not a float32
    const HeightMap back = formats::decode_gsf(formats::encode_gsf(map, {}), "r.gsf", {});
    EXPECT_EQ(back.heights_um[0], static_cast<double>(0.1F));
    map.heights_um[0] = 1e300;
    EXPECT_THROW((void)formats::encode_gsf(map, {}), InvalidArgument);
    map.heights_um.pop_back();
    EXPECT_THROW((void)formats::encode_gsf(map, {}), InvalidArgument);
}

TEST(GsfFormat, MalformedInputIsADataErrorNamingTheFile) {
    const std::string header = "XRes = 2\nYRes = 2\n";
    const std::string good = spec_gsf(header, {1, 2, 3, 4});
    EXPECT_EQ(formats::decode_gsf(good, "ok.gsf", {}).nx, 2U);
    auto expect = [](const std::string& bytes, const std::string& fragment) {
        const std::string message = gsf_error(bytes);
        EXPECT_NE(message.find("bad.gsf"), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    };
    expect("Gwyddion Simple Field 2.0\n", "not a GSF");
    expect(good.substr(0, good.size() - 2), "the data hold");
    expect(good.substr(0, 30), "NUL");
    expect(spec_gsf("XRes = 3\nYRes = 2\n", {1, 2, 3, 4}), "need 24");  // larger than the data
    expect(spec_gsf("XRes = 100000\nYRes = 100000\n", {1, 2, 3, 4}), "more than");
    expect(spec_gsf("XRes = 2\n", {1, 2, 3, 4}), "no YRes");
    expect(spec_gsf("XRes = two\nYRes = 2\n", {1, 2, 3, 4}), "positive integer");
    expect(spec_gsf(header + "XReal = 1.5.3\n", {1, 2, 3, 4}), "XReal is not a finite number");
    expect(spec_gsf(header + "ZUnits = V\n", {1, 2, 3, 4}), "not a length unit");
    expect(spec_gsf(header + "no equals sign\n", {1, 2, 3, 4}), "without '='");
    std::string bad_pad = good;
    bad_pad[header.size() + 26 + 1] = 'x';
    expect(bad_pad, "padding");
}

}  // namespace
}  // namespace roughscope::surface
