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

}  // namespace

LinearImage decode_raw(Bytes bytes, const std::string& name, const ReadOptions& options,
                       bool offered) {
    // LibRaw is large (hundreds of kB): on the heap. No memory or data error callbacks: LibRaw's
    // defaults print to stderr; its errors come back as codes and error_count().
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
    const auto& id = raw->imgdata.idata;
    const auto& color = raw->imgdata.color;
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

    const auto& data = raw->imgdata.rawdata;
    const std::size_t width = sizes.width;
    const std::size_t height = sizes.height;
    const std::size_t top = sizes.top_margin;
    const std::size_t left = sizes.left_margin;
    if (width == 0 || height == 0 || top + height > sizes.raw_height ||
        left + width > sizes.raw_width)
        throw DataError(
            concat(name, ": camera RAW visible area does not fit the sensor (corrupt)"));

    const bool cfa = id.filters != 0;
    std::size_t block = 1;
    std::size_t channels = 3;
    // plane_of[k]: the output plane of LibRaw colour index k (0 R, 1 G, 2 B, 3 the second green).
    std::size_t plane_of[4] = {0, 1, 2, 1};
    std::vector<std::uint8_t> pattern;  // colour index per site, kPatternPeriod² entries
    if (cfa) {
        if (data.raw_image == nullptr || id.colors != 3)
            throw DataError(concat(name, ": camera RAW with a ", std::to_string(id.colors),
                                   "-colour filter array is not supported (RGB only)"));
        block = id.filters == LIBRAW_XTRANS ? 3 : 2;
        pattern.resize(kPatternPeriod * kPatternPeriod);
        for (std::size_t r = 0; r < kPatternPeriod; ++r)
            for (std::size_t c = 0; c < kPatternPeriod; ++c) {
                const int k = raw->COLOR(static_cast<int>(r), static_cast<int>(c));
                if (k < 0 || k > 3)
                    throw DataError(concat(name,
                                           ": camera RAW colour filter pattern is not "
                                           "supported"));
                pattern[r * kPatternPeriod + c] = static_cast<std::uint8_t>(k);
            }
        // Every block must hold a site of each plane.
        for (std::size_t r = 0; r < kPatternPeriod; r += block)
            for (std::size_t c = 0; c < kPatternPeriod; c += block) {
                bool seen[3] = {false, false, false};
                for (std::size_t i = 0; i < block; ++i)
                    for (std::size_t j = 0; j < block; ++j)
                        seen[plane_of[pattern[(r + i) * kPatternPeriod + c + j]]] = true;
                if (!(seen[0] && seen[1] && seen[2]))
                    throw DataError(concat(name,
                                           ": camera RAW colour filter pattern without a "
                                           "red, green and blue site in every ",
                                           std::to_string(block), " x ", std::to_string(block),
                                           " block is not supported"));
            }
    } else if (data.raw_image != nullptr) {
        channels = 1;  // monochrome sensor
    } else if (data.color3_image == nullptr && data.color4_image == nullptr) {
        throw DataError(concat(name,
                               ": camera RAW layout is not supported (LibRaw gave no "
                               "integer raw data)"));
    } else if (id.colors != 3) {
        throw DataError(concat(name, ": camera RAW with ", std::to_string(id.colors),
                               " colours per pixel is not supported"));
    }
    // LibRaw's rows hold raw_pitch bytes: the visible area must lie inside them.
    const std::size_t values_per_site = data.raw_image != nullptr      ? 1
                                        : data.color4_image != nullptr ? 4
                                                                       : 3;
    if (sizes.raw_pitch / 2 < (left + width) * values_per_site)
        throw DataError(concat(name, ": camera RAW rows shorter than the visible area (corrupt)"));
    const std::size_t out_width = width / block;
    const std::size_t out_height = height / block;
    if (out_width == 0 || out_height == 0)
        throw DataError(concat(name, ": camera RAW image of ", std::to_string(width), " x ",
                               std::to_string(height), " sites is smaller than one pixel"));

    // Black levels: per colour index, plus the repeating pattern cblack[6...] (rows × columns
    // cblack[4] × cblack[5]).
    const std::size_t pattern_rows = color.cblack[4];
    const std::size_t pattern_cols = color.cblack[5];
    const bool black_pattern = pattern_rows > 0 && pattern_cols > 0 &&
                               6 + pattern_rows * pattern_cols <= LIBRAW_CBLACK_SIZE;
    auto site_black = [&](std::size_t k, std::size_t r, std::size_t c) {
        double b = static_cast<double>(color.black) + color.cblack[k];
        if (black_pattern)
            b += color.cblack[6 + (r % pattern_rows) * pattern_cols + c % pattern_cols];
        return b;
    };
    Layout layout;
    layout.width = out_width;
    layout.height = out_height;
    layout.channels = channels;
    layout.bits = std::max(1, static_cast<int>(std::bit_width(color.maximum)));
    layout.full_scale = static_cast<double>(color.maximum);
    layout.largest_code = 65535.0;  // values above the white level occur
    if (!(layout.full_scale > 0.0))
        throw DataError(concat(name, ": camera RAW white level (LibRaw maximum) is 0 (corrupt)"));
    {
        // The black level of a plane: the mean of its sites' black levels over a period of the
        // colour pattern (CFA) or of the black pattern.
        std::vector<double> sum(channels, 0.0);
        std::vector<double> count(channels, 0.0);
        const std::size_t rows = cfa ? kPatternPeriod : black_pattern ? pattern_rows : 1;
        const std::size_t cols = cfa ? kPatternPeriod : black_pattern ? pattern_cols : 1;
        for (std::size_t r = 0; r < rows; ++r)
            for (std::size_t c = 0; c < cols; ++c)
                for (std::size_t p = 0; p < channels; ++p) {
                    const std::size_t k = cfa ? pattern[r * kPatternPeriod + c] : p;
                    if (cfa && plane_of[k] != p) continue;
                    sum[p] += site_black(k, r, c);
                    count[p] += 1.0;
                }
        layout.default_black.resize(channels);
        for (std::size_t p = 0; p < channels; ++p) layout.default_black[p] = sum[p] / count[p];
    }

    LinearImage image;
    image.info.source = name;
    image.info.format = "raw";
    image.info.raw_format = raw_format_name(*raw);
    // Lossy DNG (DNG 1.4 compression 34892: JPEG-compressed 8-bit data of an already demosaiced,
    // processed image, LibRaw's lossy_dng_load_raw) holds no sensor counts.
    const bool lossy =
        std::string_view(raw->unpack_function_name()).find("lossy_dng") != std::string_view::npos;
    const Evidence evidence{Response::Linear, 0.0,
                            lossy ? "lossy DNG (LibRaw): processed values" : "camera RAW (LibRaw)"};
    if (lossy)
        image.info.warnings.push_back(concat(
            "lossy DNG (JPEG-compressed ", std::to_string(color.raw_bps),
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
    if (raw->imgdata.other.shutter > 0.0F && !facts.exposure_time_zero)
        image.info.exposure_s = raw->imgdata.other.shutter;
    if (raw->imgdata.other.aperture > 0.0F && !facts.f_number_zero)
        image.info.f_number = raw->imgdata.other.aperture;
    if (raw->imgdata.other.iso_speed > 0.0F) image.info.iso = raw->imgdata.other.iso_speed;
    if (sizes.flip != 0)
        image.info.warnings.push_back(concat("RAW orientation (LibRaw flip ",
                                             std::to_string(sizes.flip),
                                             ") not applied: the pixels are in sensor order"));
    Linearizer lin(image, layout, evidence, options);
    lin.mark_every_row_written();  // the loops below write every value and flag (=, not |=)

    // The linear code of every 16-bit value, and the per-site black unless the options override.
    std::vector<float> linear(std::size_t{1} << 16);
    for (std::size_t q = 0; q < linear.size(); ++q)
        linear[q] = static_cast<float>(lin.linear_code(static_cast<double>(q)));
    const bool given_black = options.black_level_dn.has_value();
    const double white = lin.white();
    std::vector<double> plane_black(channels);
    std::vector<double> inverse_range(channels);
    for (std::size_t p = 0; p < channels; ++p) {
        plane_black[p] = lin.black(p);
        inverse_range[p] = 1.0 / (white - plane_black[p]);
    }
    std::vector<double> balance(channels, 1.0);
    if (options.white_balance && channels == 3) {
        const float* mul = color.cam_mul;
        // Multipliers beyond 1e-4 .. 1e4 of green are no white balance a camera records.
        bool usable = std::isfinite(mul[1]) && mul[1] > 0.0F;
        for (std::size_t p = 0; usable && p < 3; ++p) {
            const double ratio = static_cast<double>(mul[p]) / mul[1];
            usable = std::isfinite(ratio) && ratio >= 1e-4 && ratio <= 1e4;
        }
        if (usable) {
            for (std::size_t p = 0; p < 3; ++p) balance[p] = static_cast<double>(mul[p]) / mul[1];
        } else {
            image.info.warnings.push_back(
                "white_balance: the file has no usable camera white balance; values left as "
                "stored");
        }
    }

    for (std::size_t p = 0; p < channels; ++p)
        if (!(65535.0 * inverse_range[p] * balance[p] <= std::numeric_limits<float>::max()))
            throw InvalidArgument(concat(name,
                                         ": the levels and white balance give linear "
                                         "values beyond the float range"));

    const std::size_t pitch = sizes.raw_pitch;  // bytes per raw row
    float* values = image.values.data();
    std::uint8_t* flags = image.flags.data();
    const std::size_t plane_size = out_width * out_height;
    if (cfa) {
        // Per cell of the colour pattern: the plane and, when the black pattern repeats within
        // kPatternPeriod (always in practice), the black level.
        const bool black_per_cell =
            given_black || !black_pattern ||
            (kPatternPeriod % pattern_rows == 0 && kPatternPeriod % pattern_cols == 0);
        std::vector<std::uint8_t> cell_plane(kPatternPeriod * kPatternPeriod);
        std::vector<double> cell_black(kPatternPeriod * kPatternPeriod);
        for (std::size_t r = 0; r < kPatternPeriod; ++r)
            for (std::size_t c = 0; c < kPatternPeriod; ++c) {
                const std::size_t k = pattern[r * kPatternPeriod + c];
                cell_plane[r * kPatternPeriod + c] = static_cast<std::uint8_t>(plane_of[k]);
                cell_black[r * kPatternPeriod + c] =
                    given_black ? plane_black[plane_of[k]] : site_black(k, r, c);
            }
        const std::uint16_t* base = data.raw_image;
        const std::size_t row_sites = pitch / 2;
        // The common case: a 2 x 2 pattern of colours and black levels (Bayer), one site of R and
        // B and two of G per block.
        bool bayer_2x2 = block == 2 && black_per_cell;
        for (std::size_t cell = 0; bayer_2x2 && cell < cell_plane.size(); ++cell) {
            const std::size_t same = (cell / kPatternPeriod % 2) * kPatternPeriod + cell % 2;
            bayer_2x2 =
                cell_plane[cell] == cell_plane[same] && cell_black[cell] == cell_black[same];
        }
        if (bayer_2x2) {
            const std::size_t site_cell[4] = {0, 1, kPatternPeriod, kPatternPeriod + 1};
            std::size_t plane[4];
            float black[4];
            double count[3] = {0.0, 0.0, 0.0};
            for (std::size_t k = 0; k < 4; ++k) {
                plane[k] = cell_plane[site_cell[k]];
                black[k] = static_cast<float>(cell_black[site_cell[k]]);
                count[plane[k]] += 1.0;
            }
            bayer_2x2 = count[0] == 1.0 && count[1] == 2.0 && count[2] == 1.0;
            float gain[3];
            for (std::size_t q = 0; q < 3; ++q)
                gain[q] = static_cast<float>(inverse_range[q] * balance[q] / count[q]);
            const float white_f = static_cast<float>(white);
            for (std::size_t by = 0; bayer_2x2 && by < out_height; ++by) {
                const std::uint16_t* row0 = base + (top + 2 * by) * row_sites + left;
                const std::uint16_t* row1 = row0 + row_sites;
                for (std::size_t bx = 0; bx < out_width; ++bx) {
                    const float v[4] = {linear[row0[2 * bx]], linear[row0[2 * bx + 1]],
                                        linear[row1[2 * bx]], linear[row1[2 * bx + 1]]};
                    float sum[3] = {0.0F, 0.0F, 0.0F};
                    std::uint8_t f = 0;
                    for (std::size_t k = 0; k < 4; ++k) {
                        sum[plane[k]] += v[k] - black[k];
                        f |= static_cast<std::uint8_t>((v[k] >= white_f ? kPixelSaturated : 0) |
                                                       (v[k] <= black[k] ? kPixelClippedLow : 0));
                    }
                    const std::size_t at = by * out_width + bx;
                    for (std::size_t q = 0; q < 3; ++q)
                        values[q * plane_size + at] = sum[q] * gain[q];
                    flags[at] = f;
                }
            }
        }
        for (std::size_t by = 0; !bayer_2x2 && by < out_height; ++by) {
            const std::size_t r0 = by * block;
            for (std::size_t bx = 0; bx < out_width; ++bx) {
                const std::size_t c0 = bx * block;
                const std::size_t column_cell = c0 % kPatternPeriod;  // + j stays < period
                double sum[3] = {0.0, 0.0, 0.0};
                int count[3] = {0, 0, 0};
                std::uint8_t f = 0;
                for (std::size_t i = 0; i < block; ++i) {
                    const std::size_t r = r0 + i;
                    const std::uint16_t* row = base + (top + r) * row_sites + left + c0;
                    const std::size_t cell_row =
                        (r % kPatternPeriod) * kPatternPeriod + column_cell;
                    for (std::size_t j = 0; j < block; ++j) {
                        const std::size_t cell = cell_row + j;
                        const std::size_t p = cell_plane[cell];
                        const double v = linear[row[j]];
                        const double b = black_per_cell ? cell_black[cell]
                                                        : site_black(pattern[cell], r, c0 + j);
                        sum[p] += v - b;
                        count[p] += 1;
                        if (v >= white) f |= kPixelSaturated;
                        if (v <= b) f |= kPixelClippedLow;
                    }
                }
                const std::size_t at = by * out_width + bx;
                for (std::size_t p = 0; p < 3; ++p)
                    values[p * plane_size + at] =
                        static_cast<float>(sum[p] / count[p] * inverse_range[p] * balance[p]);
                flags[at] = f;
            }
        }
    } else {
        const std::size_t stride = values_per_site;
        const std::uint16_t* base = data.raw_image != nullptr      ? data.raw_image
                                    : data.color4_image != nullptr ? &data.color4_image[0][0]
                                                                   : &data.color3_image[0][0];
        const std::size_t row_values = pitch / 2;
        if ((given_black || !black_pattern) && channels == 3) {
            // One black level per plane (the usual case): the same arithmetic with the levels
            // and gains hoisted out of the loop; one read of the raw rows.
            double b[3];
            for (std::size_t p = 0; p < 3; ++p)
                b[p] = given_black ? plane_black[p] : site_black(p, 0, 0);
            float* out[3] = {values, values + plane_size, values + 2 * plane_size};
            for (std::size_t r = 0; r < out_height; ++r) {
                const std::uint16_t* row = base + (top + r) * row_values + left * stride;
                const std::size_t at0 = r * out_width;
                for (std::size_t x = 0; x < out_width; ++x) {
                    const std::uint16_t* site = row + x * stride;
                    std::uint8_t f = 0;
                    for (std::size_t p = 0; p < 3; ++p) {
                        const double v = linear[site[p]];
                        f |= static_cast<std::uint8_t>((v >= white ? kPixelSaturated : 0) |
                                                       (v <= b[p] ? kPixelClippedLow : 0));
                        out[p][at0 + x] =
                            static_cast<float>((v - b[p]) * inverse_range[p] * balance[p]);
                    }
                    flags[at0 + x] = f;
                }
            }
            return image;
        }
        for (std::size_t r = 0; r < out_height; ++r) {
            const std::uint16_t* row = base + (top + r) * row_values + left * stride;
            for (std::size_t x = 0; x < out_width; ++x) {
                std::uint8_t f = 0;
                for (std::size_t p = 0; p < channels; ++p) {
                    const double s = linear[row[x * stride + p]];
                    const double b = given_black ? plane_black[p] : site_black(p, r, x);
                    if (s >= white) f |= kPixelSaturated;
                    if (s <= b) f |= kPixelClippedLow;
                    values[p * plane_size + r * out_width + x] =
                        static_cast<float>((s - b) * inverse_range[p] * balance[p]);
                }
                flags[r * out_width + x] = f;
            }
        }
    }
    return image;
}

}  // namespace roughscope::image::detail
