// Camera RAW files through LibRaw (read.hpp; docs/image.md "Camera RAW"). LibRaw opens and unpacks
// the file; no LibRaw processing follows (no demosaicing, white balance, colour matrix, gamma or
// brightening): the sensor values are read here from LibRaw's raw buffers.
//  * Colour-filter-array sensors (Bayer, X-Trans): every block of 2 x 2 (Bayer) or 3 x 3 (X-Trans)
//    sites becomes one RGB pixel, each plane the mean of the block's sites of that colour (the two
//    greens of a Bayer block averaged). Edge rows and columns that do not fill a block are dropped.
//  * Three-colour linear images (DNG LinearRaw, sRAW): one RGB pixel per site; monochrome
//    sensors: one grey pixel per site.
// Per site: s = linear code of the stored value, black = LibRaw's black level for the site
// (color.black + cblack[colour] + the cblack pattern); flags from s against the white level
// (LibRaw's maximum) and the site's black. value = mean(s − black) / (white − black of the plane).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <libraw/libraw.h>

#include "decode.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {

namespace {

// Raw data holds at most this many sites per byte of file (lossless-JPEG raw data needs at least
// 1 bit a site; this leaves 8 times more room).
constexpr std::uint64_t kRawMaxSitesPerByte = 64;
// The colour of a site repeats with a period dividing 48 (Bayer 8 x 2, X-Trans 6 x 6, Leaf 16).
constexpr std::size_t kPatternPeriod = 48;

std::string trimmed(const char* text) {
    std::string s(text);
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

std::string raw_format_name(const LibRaw& raw) {
    const auto& id = raw.imgdata.idata;
    std::string name = trimmed(id.make);
    const std::string model = trimmed(id.model);
    if (!model.empty()) name = name.empty() ? model : concat(name, " ", model);
    if (id.dng_version != 0) name = name.empty() ? std::string("DNG") : concat(name, " (DNG)");
    return name;
}

// LibRaw on the file, unpacked; DataError for a file it cannot open or unpack. LibRaw is large
// (hundreds of kB): on the heap. No memory or data error callbacks: LibRaw's defaults print to
// stderr; its errors come back as codes and error_count().
std::unique_ptr<LibRaw> open_raw(Bytes bytes, const std::string& name, bool offered) {
    auto raw = std::make_unique<LibRaw>(LIBRAW_OPIONS_NO_MEMERR_CALLBACK |
                                        LIBRAW_OPIONS_NO_DATAERR_CALLBACK);
    const int opened = raw->open_buffer(const_cast<std::uint8_t*>(bytes.data()), bytes.size());
    if (opened != LIBRAW_SUCCESS) {
        if (offered)
            throw DataError(concat(name,
                                   ": not a PNG, JPEG, TIFF or camera RAW file that can be "
                                   "read (LibRaw: ",
                                   LibRaw::strerror(opened), ")"));
        throw DataError(
            concat(name, ": camera RAW file LibRaw cannot open (", LibRaw::strerror(opened), ")"));
    }
    const auto& sizes = raw->imgdata.sizes;
    const std::size_t raw_sites = std::size_t{sizes.raw_width} * sizes.raw_height;
    check_pixel_count(name, sizes.raw_width, sizes.raw_height);
    check_expansion(name, raw_sites, bytes.size(), kRawMaxSitesPerByte, "camera RAW header");
    if (raw->is_fuji_rotated() != 0)
        throw DataError(concat(name, ": Fuji SuperCCD (rotated) sensors are not supported"));
    const int unpacked = raw->unpack();
    if (unpacked != LIBRAW_SUCCESS)
        throw DataError(concat(name, ": camera RAW data cannot be unpacked (LibRaw: ",
                               LibRaw::strerror(unpacked), "; truncated or corrupt)"));
    if (raw->error_count() > 0)
        throw DataError(concat(name, ": camera RAW data truncated or corrupt (LibRaw reported ",
                               std::to_string(raw->error_count()), " data errors)"));
    return raw;
}

// The unpacked sensor: the visible area, the colour filter pattern and the black levels.
struct Sensor {
    const LibRaw* raw = nullptr;
    std::size_t width = 0;  // visible sites
    std::size_t height = 0;
    std::size_t top = 0;
    std::size_t left = 0;
    bool cfa = false;
    std::size_t block = 1;  // sites per pixel side
    std::size_t channels = 3;
    // plane_of[k]: the output plane of LibRaw colour index k (0 R, 1 G, 2 B, 3 the second green).
    std::size_t plane_of[4] = {0, 1, 2, 1};
    std::vector<std::uint8_t> pattern;  // colour index per site, kPatternPeriod² entries
    std::size_t values_per_site = 1;
    std::size_t out_width = 0;
    std::size_t out_height = 0;
    // The repeating black pattern cblack[6...] (rows × columns cblack[4] × cblack[5]).
    std::size_t pattern_rows = 0;
    std::size_t pattern_cols = 0;
    bool black_pattern = false;

    const libraw_colordata_t& color() const { return raw->imgdata.color; }
    // The black level of site (r, c) of colour index k.
    double site_black(std::size_t k, std::size_t r, std::size_t c) const {
        const auto& color = raw->imgdata.color;
        double b = static_cast<double>(color.black) + color.cblack[k];
        if (black_pattern)
            b += color.cblack[6 + (r % pattern_rows) * pattern_cols + c % pattern_cols];
        return b;
    }
};

// The colour filter pattern over a period; DataError unless every block holds a red, a green and
// a blue site.
void read_cfa_pattern(Sensor& s, LibRaw& raw, const std::string& name) {
    const auto& id = raw.imgdata.idata;
    if (raw.imgdata.rawdata.raw_image == nullptr || id.colors != 3)
        throw DataError(concat(name, ": camera RAW with a ", std::to_string(id.colors),
                               "-colour filter array is not supported (RGB only)"));
    s.block = id.filters == LIBRAW_XTRANS ? 3 : 2;
    s.pattern.resize(kPatternPeriod * kPatternPeriod);
    for (std::size_t r = 0; r < kPatternPeriod; ++r)
        for (std::size_t c = 0; c < kPatternPeriod; ++c) {
            const int k = raw.COLOR(static_cast<int>(r), static_cast<int>(c));
            if (k < 0 || k > 3)
                throw DataError(concat(name,
                                       ": camera RAW colour filter pattern is not "
                                       "supported"));
            s.pattern[r * kPatternPeriod + c] = static_cast<std::uint8_t>(k);
        }
    const std::size_t block = s.block;
    for (std::size_t r = 0; r < kPatternPeriod; r += block)
        for (std::size_t c = 0; c < kPatternPeriod; c += block) {
            bool seen[3] = {false, false, false};
            for (std::size_t i = 0; i < block; ++i)
                for (std::size_t j = 0; j < block; ++j)
                    seen[s.plane_of[s.pattern[(r + i) * kPatternPeriod + c + j]]] = true;
            if (!(seen[0] && seen[1] && seen[2]))
                throw DataError(concat(name,
                                       ": camera RAW colour filter pattern without a "
                                       "red, green and blue site in every ",
                                       std::to_string(block), " x ", std::to_string(block),
                                       " block is not supported"));
        }
}

// What the unpacked data hold, checked against LibRaw's buffers; DataError for a layout that is
// not supported or does not fit.
Sensor describe_sensor(LibRaw& raw, const std::string& name) {
    const auto& sizes = raw.imgdata.sizes;
    const auto& id = raw.imgdata.idata;
    const auto& data = raw.imgdata.rawdata;
    Sensor s;
    s.raw = &raw;
    s.width = sizes.width;
    s.height = sizes.height;
    s.top = sizes.top_margin;
    s.left = sizes.left_margin;
    if (s.width == 0 || s.height == 0 || s.top + s.height > sizes.raw_height ||
        s.left + s.width > sizes.raw_width)
        throw DataError(
            concat(name, ": camera RAW visible area does not fit the sensor (corrupt)"));
    s.cfa = id.filters != 0;
    if (s.cfa) {
        read_cfa_pattern(s, raw, name);
    } else if (data.raw_image != nullptr) {
        s.channels = 1;  // monochrome sensor
    } else if (data.color3_image == nullptr && data.color4_image == nullptr) {
        throw DataError(concat(name,
                               ": camera RAW layout is not supported (LibRaw gave no "
                               "integer raw data)"));
    } else if (id.colors != 3) {
        throw DataError(concat(name, ": camera RAW with ", std::to_string(id.colors),
                               " colours per pixel is not supported"));
    }
    // LibRaw's rows hold raw_pitch bytes: the visible area must lie inside them.
    s.values_per_site = data.raw_image != nullptr ? 1 : data.color4_image != nullptr ? 4 : 3;
    if (sizes.raw_pitch / 2 < (s.left + s.width) * s.values_per_site)
        throw DataError(concat(name, ": camera RAW rows shorter than the visible area (corrupt)"));
    s.out_width = s.width / s.block;
    s.out_height = s.height / s.block;
    if (s.out_width == 0 || s.out_height == 0)
        throw DataError(concat(name, ": camera RAW image of ", std::to_string(s.width), " x ",
                               std::to_string(s.height), " sites is smaller than one pixel"));
    const auto& color = raw.imgdata.color;
    s.pattern_rows = color.cblack[4];
    s.pattern_cols = color.cblack[5];
    s.black_pattern = s.pattern_rows > 0 && s.pattern_cols > 0 &&
                      6 + s.pattern_rows * s.pattern_cols <= LIBRAW_CBLACK_SIZE;
    return s;
}

// The layout for the linearizer: the white level and, per plane, the mean of its sites' black
// levels over a period of the colour pattern (CFA) or of the black pattern.
Layout raw_layout(const Sensor& s, const std::string& name) {
    const auto& color = s.color();
    Layout layout;
    layout.width = s.out_width;
    layout.height = s.out_height;
    layout.channels = s.channels;
    layout.bits = std::max(1, static_cast<int>(std::bit_width(color.maximum)));
    layout.full_scale = static_cast<double>(color.maximum);
    layout.largest_code = 65535.0;  // values above the white level occur
    if (!(layout.full_scale > 0.0))
        throw DataError(concat(name, ": camera RAW white level (LibRaw maximum) is 0 (corrupt)"));
    std::vector<double> sum(s.channels, 0.0);
    std::vector<double> count(s.channels, 0.0);
    const std::size_t rows = s.cfa ? kPatternPeriod : s.black_pattern ? s.pattern_rows : 1;
    const std::size_t cols = s.cfa ? kPatternPeriod : s.black_pattern ? s.pattern_cols : 1;
    for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t c = 0; c < cols; ++c)
            for (std::size_t p = 0; p < s.channels; ++p) {
                const std::size_t k = s.cfa ? s.pattern[r * kPatternPeriod + c] : p;
                if (s.cfa && s.plane_of[k] != p) continue;
                sum[p] += s.site_black(k, r, c);
                count[p] += 1.0;
            }
    layout.default_black.resize(s.channels);
    for (std::size_t p = 0; p < s.channels; ++p) layout.default_black[p] = sum[p] / count[p];
    return layout;
}

// The file's format, exposure and warnings into info; the evidence of the response (linear
// sensor counts, or a lossy DNG's processed values).
Evidence read_raw_metadata(LibRaw& raw, Bytes bytes, const std::string& name, ImageInfo& info) {
    info.raw_format = raw_format_name(raw);
    // Lossy DNG (DNG 1.4 compression 34892: JPEG-compressed 8-bit data of an already demosaiced,
    // processed image, LibRaw's lossy_dng_load_raw) holds no sensor counts.
    const bool lossy =
        std::string_view(raw.unpack_function_name()).find("lossy_dng") != std::string_view::npos;
    if (lossy)
        info.warnings.push_back(concat(
            "lossy DNG (JPEG-compressed ", std::to_string(raw.imgdata.color.raw_bps),
            "-bit \"Linear Raw\" data): the values are processed (demosaiced and converted by "
            "the software that wrote the file, quantised and lossily compressed), not linear "
            "sensor counts; a roughness measured from them is not reliable: use the camera's own "
            "RAW file"));
    // An exposure time or f-number the file records as 0 is unknown, whatever LibRaw derives.
    RawTiffFacts facts;
    // (TIFF-structured files only: those starting II or MM but Canon's CRW, as in read.cpp.)
    const bool crw =
        bytes.size() >= 14 &&
        std::string_view(reinterpret_cast<const char*>(bytes.data() + 6), 8) == "HEAPCCDR";
    if (bytes.size() >= 8 && (bytes[0] == 'I' || bytes[0] == 'M') && bytes[1] == bytes[0] && !crw)
        facts = check_raw_structure(bytes, name, true);
    const auto& other = raw.imgdata.other;
    if (other.shutter > 0.0F && !facts.exposure_time_zero) info.exposure_s = other.shutter;
    if (other.aperture > 0.0F && !facts.f_number_zero) info.f_number = other.aperture;
    if (other.iso_speed > 0.0F) info.iso = other.iso_speed;
    const auto flip = raw.imgdata.sizes.flip;
    if (flip != 0)
        info.warnings.push_back(concat("RAW orientation (LibRaw flip ", std::to_string(flip),
                                       ") not applied: the pixels are in sensor order"));
    return {Response::Linear, 0.0,
            lossy ? "lossy DNG (LibRaw): processed values" : "camera RAW (LibRaw)"};
}

// From a stored value to a value on the linear scale: the linear code of every 16-bit value, the
// levels (the per-site black unless the options give one per plane) and the white balance.
struct Scaling {
    std::vector<float> linear;
    bool given_black = false;
    double white = 1.0;
    std::vector<double> plane_black;
    std::vector<double> inverse_range;
    std::vector<double> balance;
};

// The camera's white balance relative to green, when asked for and usable (else 1 and a
// warning).
std::vector<double> white_balance(const Sensor& s, const ReadOptions& options, ImageInfo& info) {
    std::vector<double> balance(s.channels, 1.0);
    if (!options.white_balance || s.channels != 3) return balance;
    const float* mul = s.color().cam_mul;
    // Multipliers beyond 1e-4 .. 1e4 of green are no white balance a camera records.
    bool usable = std::isfinite(mul[1]) && mul[1] > 0.0F;
    for (std::size_t p = 0; usable && p < 3; ++p) {
        const double ratio = static_cast<double>(mul[p]) / mul[1];
        usable = std::isfinite(ratio) && ratio >= 1e-4 && ratio <= 1e4;
    }
    if (usable) {
        for (std::size_t p = 0; p < 3; ++p) balance[p] = static_cast<double>(mul[p]) / mul[1];
    } else {
        info.warnings.push_back(
            "white_balance: the file has no usable camera white balance; values left as "
            "stored");
    }
    return balance;
}

Scaling raw_scaling(const Sensor& s, const Linearizer& lin, const ReadOptions& options,
                    const std::string& name, ImageInfo& info) {
    Scaling k;
    k.linear.resize(std::size_t{1} << 16);
    for (std::size_t q = 0; q < k.linear.size(); ++q)
        k.linear[q] = static_cast<float>(lin.linear_code(static_cast<double>(q)));
    k.given_black = options.black_level_dn.has_value();
    k.white = lin.white();
    k.plane_black.resize(s.channels);
    k.inverse_range.resize(s.channels);
    for (std::size_t p = 0; p < s.channels; ++p) {
        k.plane_black[p] = lin.black(p);
        k.inverse_range[p] = 1.0 / (k.white - k.plane_black[p]);
    }
    k.balance = white_balance(s, options, info);
    for (std::size_t p = 0; p < s.channels; ++p)
        if (!(65535.0 * k.inverse_range[p] * k.balance[p] <= std::numeric_limits<float>::max()))
            throw InvalidArgument(concat(name,
                                         ": the levels and white balance give linear "
                                         "values beyond the float range"));
    return k;
}

// Per cell of the colour pattern: its plane and black level (when the black pattern repeats
// within kPatternPeriod, always in practice: black_per_cell).
struct Cells {
    bool black_per_cell = true;
    std::vector<std::uint8_t> plane;
    std::vector<double> black;
};

Cells pattern_cells(const Sensor& s, const Scaling& k) {
    Cells cells;
    cells.black_per_cell =
        k.given_black || !s.black_pattern ||
        (kPatternPeriod % s.pattern_rows == 0 && kPatternPeriod % s.pattern_cols == 0);
    cells.plane.resize(kPatternPeriod * kPatternPeriod);
    cells.black.resize(kPatternPeriod * kPatternPeriod);
    for (std::size_t r = 0; r < kPatternPeriod; ++r)
        for (std::size_t c = 0; c < kPatternPeriod; ++c) {
            const std::size_t at = r * kPatternPeriod + c;
            const std::size_t colour = s.pattern[at];
            cells.plane[at] = static_cast<std::uint8_t>(s.plane_of[colour]);
            cells.black[at] =
                k.given_black ? k.plane_black[s.plane_of[colour]] : s.site_black(colour, r, c);
        }
    return cells;
}

// The common case: a 2 x 2 pattern of colours and black levels (Bayer), one site of R and B and
// two of G per block. False (nothing written) when the pattern is another.
bool convert_bayer_2x2(const Sensor& s, const Scaling& k, const Cells& cells, LinearImage& image) {
    bool bayer_2x2 = s.block == 2 && cells.black_per_cell;
    for (std::size_t cell = 0; bayer_2x2 && cell < cells.plane.size(); ++cell) {
        const std::size_t same = (cell / kPatternPeriod % 2) * kPatternPeriod + cell % 2;
        bayer_2x2 =
            cells.plane[cell] == cells.plane[same] && cells.black[cell] == cells.black[same];
    }
    if (!bayer_2x2) return false;
    const std::size_t site_cell[4] = {0, 1, kPatternPeriod, kPatternPeriod + 1};
    std::size_t plane[4];
    float black[4];
    double count[3] = {0.0, 0.0, 0.0};
    for (std::size_t i = 0; i < 4; ++i) {
        plane[i] = cells.plane[site_cell[i]];
        black[i] = static_cast<float>(cells.black[site_cell[i]]);
        count[plane[i]] += 1.0;
    }
    if (!(count[0] == 1.0 && count[1] == 2.0 && count[2] == 1.0)) return false;
    float gain[3];
    for (std::size_t q = 0; q < 3; ++q)
        gain[q] = static_cast<float>(k.inverse_range[q] * k.balance[q] / count[q]);
    const float white_f = static_cast<float>(k.white);
    const std::uint16_t* base = s.raw->imgdata.rawdata.raw_image;
    const std::size_t row_sites = s.raw->imgdata.sizes.raw_pitch / 2;
    const std::size_t plane_size = s.out_width * s.out_height;
    const float* linear = k.linear.data();
    float* values = image.values.data();
    std::uint8_t* flags = image.flags.data();
    for (std::size_t by = 0; by < s.out_height; ++by) {
        const std::uint16_t* row0 = base + (s.top + 2 * by) * row_sites + s.left;
        const std::uint16_t* row1 = row0 + row_sites;
        for (std::size_t bx = 0; bx < s.out_width; ++bx) {
            const float v[4] = {linear[row0[2 * bx]], linear[row0[2 * bx + 1]],
                                linear[row1[2 * bx]], linear[row1[2 * bx + 1]]};
            float sum[3] = {0.0F, 0.0F, 0.0F};
            std::uint8_t f = 0;
            for (std::size_t i = 0; i < 4; ++i) {
                sum[plane[i]] += v[i] - black[i];
                f |= static_cast<std::uint8_t>((v[i] >= white_f ? kPixelSaturated : 0) |
                                               (v[i] <= black[i] ? kPixelClippedLow : 0));
            }
            const std::size_t at = by * s.out_width + bx;
            for (std::size_t q = 0; q < 3; ++q) values[q * plane_size + at] = sum[q] * gain[q];
            flags[at] = f;
        }
    }
    return true;
}

// Any colour filter pattern: each plane of a pixel the mean of its block's sites of that colour.
void convert_cfa_blocks(const Sensor& s, const Scaling& k, const Cells& cells, LinearImage& image) {
    const std::uint16_t* base = s.raw->imgdata.rawdata.raw_image;
    const std::size_t row_sites = s.raw->imgdata.sizes.raw_pitch / 2;
    const std::size_t plane_size = s.out_width * s.out_height;
    const std::size_t block = s.block;
    float* values = image.values.data();
    std::uint8_t* flags = image.flags.data();
    for (std::size_t by = 0; by < s.out_height; ++by) {
        const std::size_t r0 = by * block;
        for (std::size_t bx = 0; bx < s.out_width; ++bx) {
            const std::size_t c0 = bx * block;
            const std::size_t column_cell = c0 % kPatternPeriod;  // + j stays < period
            double sum[3] = {0.0, 0.0, 0.0};
            int count[3] = {0, 0, 0};
            std::uint8_t f = 0;
            for (std::size_t i = 0; i < block; ++i) {
                const std::size_t r = r0 + i;
                const std::uint16_t* row = base + (s.top + r) * row_sites + s.left + c0;
                const std::size_t cell_row = (r % kPatternPeriod) * kPatternPeriod + column_cell;
                for (std::size_t j = 0; j < block; ++j) {
                    const std::size_t cell = cell_row + j;
                    const std::size_t p = cells.plane[cell];
                    const double v = k.linear[row[j]];
                    const double b = cells.black_per_cell
                                         ? cells.black[cell]
                                         : s.site_black(s.pattern[cell], r, c0 + j);
                    sum[p] += v - b;
                    count[p] += 1;
                    if (v >= k.white) f |= kPixelSaturated;
                    if (v <= b) f |= kPixelClippedLow;
                }
            }
            const std::size_t at = by * s.out_width + bx;
            for (std::size_t p = 0; p < 3; ++p)
                values[p * plane_size + at] =
                    static_cast<float>(sum[p] / count[p] * k.inverse_range[p] * k.balance[p]);
            flags[at] = f;
        }
    }
}

// Three-colour linear images and monochrome sensors: one pixel per site.
void convert_sites(const Sensor& s, const Scaling& k, LinearImage& image) {
    const auto& data = s.raw->imgdata.rawdata;
    const std::size_t stride = s.values_per_site;
    const std::uint16_t* base = data.raw_image != nullptr      ? data.raw_image
                                : data.color4_image != nullptr ? &data.color4_image[0][0]
                                                               : &data.color3_image[0][0];
    const std::size_t row_values = s.raw->imgdata.sizes.raw_pitch / 2;
    const std::size_t plane_size = s.out_width * s.out_height;
    float* values = image.values.data();
    std::uint8_t* flags = image.flags.data();
    if ((k.given_black || !s.black_pattern) && s.channels == 3) {
        // One black level per plane (the usual case): the same arithmetic with the levels and
        // gains hoisted out of the loop; one read of the raw rows.
        double b[3];
        for (std::size_t p = 0; p < 3; ++p)
            b[p] = k.given_black ? k.plane_black[p] : s.site_black(p, 0, 0);
        float* out[3] = {values, values + plane_size, values + 2 * plane_size};
        for (std::size_t r = 0; r < s.out_height; ++r) {
            const std::uint16_t* row = base + (s.top + r) * row_values + s.left * stride;
            const std::size_t at0 = r * s.out_width;
            for (std::size_t x = 0; x < s.out_width; ++x) {
                const std::uint16_t* site = row + x * stride;
                std::uint8_t f = 0;
                for (std::size_t p = 0; p < 3; ++p) {
                    const double v = k.linear[site[p]];
                    f |= static_cast<std::uint8_t>((v >= k.white ? kPixelSaturated : 0) |
                                                   (v <= b[p] ? kPixelClippedLow : 0));
                    out[p][at0 + x] =
                        static_cast<float>((v - b[p]) * k.inverse_range[p] * k.balance[p]);
                }
                flags[at0 + x] = f;
            }
        }
        return;
    }
    for (std::size_t r = 0; r < s.out_height; ++r) {
        const std::uint16_t* row = base + (s.top + r) * row_values + s.left * stride;
        for (std::size_t x = 0; x < s.out_width; ++x) {
            std::uint8_t f = 0;
            for (std::size_t p = 0; p < s.channels; ++p) {
                const double v = k.linear[row[x * stride + p]];
                const double b = k.given_black ? k.plane_black[p] : s.site_black(p, r, x);
                if (v >= k.white) f |= kPixelSaturated;
                if (v <= b) f |= kPixelClippedLow;
                values[p * plane_size + r * s.out_width + x] =
                    static_cast<float>((v - b) * k.inverse_range[p] * k.balance[p]);
            }
            flags[r * s.out_width + x] = f;
        }
    }
}

}  // namespace

LinearImage decode_raw(Bytes bytes, const std::string& name, const ReadOptions& options,
                       bool offered) {
    const std::unique_ptr<LibRaw> raw = open_raw(bytes, name, offered);
    const Sensor sensor = describe_sensor(*raw, name);
    const Layout layout = raw_layout(sensor, name);
    LinearImage image;
    image.info.source = name;
    image.info.format = "raw";
    const Evidence evidence = read_raw_metadata(*raw, bytes, name, image.info);
    Linearizer lin(image, layout, evidence, options);
    lin.mark_every_row_written();  // the conversions write every value and flag (=, not |=)
    const Scaling scaling = raw_scaling(sensor, lin, options, name, image.info);
    if (sensor.cfa) {
        const Cells cells = pattern_cells(sensor, scaling);
        if (!convert_bayer_2x2(sensor, scaling, cells, image))
            convert_cfa_blocks(sensor, scaling, cells, image);
    } else {
        convert_sites(sensor, scaling, image);
    }
    return image;
}

}  // namespace roughscope::image::detail
