// Files of a roughness map (maps/map_files.hpp, docs/maps.md "Files"): float TIFF and PNG
// encoded in memory by io's codecs (src/io/tiff_codec.hpp, png_codec.hpp); colour maps and text
// through OpenCV imgproc.
#include "roughscope/maps/map_files.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "io/png_codec.hpp"
#include "io/tiff_codec.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image {
namespace {

void check_layer(std::size_t size, std::size_t width, std::size_t height, std::size_t max_side,
                 std::string_view what) {
    if (width == 0 || height == 0 || width > max_side || height > max_side)
        throw InvalidArgument(concat(what, ": the map is ", std::to_string(width), " x ",
                                     std::to_string(height), "; each side must be in [1, ",
                                     std::to_string(max_side), "]"));
    if (size != width * height)
        throw InvalidArgument(concat(what, ": the layer has ", std::to_string(size),
                                     " values but the map is ", std::to_string(width), " x ",
                                     std::to_string(height)));
}

constexpr std::size_t kMaxTiffSide = std::size_t{1} << 31;
constexpr std::size_t kMaxPngSide = 65535;

namespace codec = io::codec;

// An 8-bit RGB cv::Mat (CV_8UC3, R G B order) as PNG.
std::string encode_rgb_png(const cv::Mat& rgb) {
    return codec::encode_png({rgb.data,
                              static_cast<std::size_t>(rgb.cols),
                              static_cast<std::size_t>(rgb.rows),
                              3,
                              {8, false},
                              rgb.step[0]});
}

// ---- colours --------------------------------------------------------------------------------

// OpenCV's VIRIDIS as 256 RGB entries.
const std::vector<std::array<std::uint8_t, 3>>& viridis() {
    static const std::vector<std::array<std::uint8_t, 3>> lut = [] {
        cv::Mat ramp(1, 256, CV_8UC1);
        for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
        cv::Mat bgr;
        cv::applyColorMap(ramp, bgr, cv::COLORMAP_VIRIDIS);
        std::vector<std::array<std::uint8_t, 3>> out(256);
        for (int i = 0; i < 256; ++i) {
            const cv::Vec3b c = bgr.at<cv::Vec3b>(0, i);
            out[static_cast<std::size_t>(i)] = {c[2], c[1], c[0]};
        }
        return out;
    }();
    return lut;
}

void check_range(ColourRange range) {
    if (!(std::isfinite(range.lower) && std::isfinite(range.upper) && range.lower < range.upper))
        throw InvalidArgument(
            concat("map png: the colour range [", check::format_number(range.lower), ", ",
                   check::format_number(range.upper), "] must be finite with lower < upper"));
}

int colour_index(double v, ColourRange range) {
    const double t = (v - range.lower) / (range.upper - range.lower);
    return static_cast<int>(std::lround(std::clamp(t, 0.0, 1.0) * 255.0));
}

std::string tick_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return text;
}

// The integer enlargement that brings the longer side to at least 256 pixels (at most 64).
int enlargement(std::size_t width, std::size_t height) {
    const std::size_t longer = std::max(width, height);
    if (longer >= 256) return 1;
    return static_cast<int>(std::min<std::size_t>(64, (256 + longer - 1) / longer));
}

void put_text(cv::Mat& rgb, const std::string& text, int x, int y) {
    cv::putText(rgb, text, cv::Point(x, y), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
}

}  // namespace

ColourRange finite_range(std::span<const float> layer) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const float v : layer)
        if (std::isfinite(v)) {
            lo = std::min(lo, static_cast<double>(v));
            hi = std::max(hi, static_cast<double>(v));
        }
    if (!(lo <= hi)) return {0.0, 1.0};
    if (lo == hi) return {lo - 0.5, hi + 0.5};
    return {lo, hi};
}

std::array<std::uint8_t, 3> map_colour(float value, ColourRange range) {
    if (!std::isfinite(value)) return {kMissingGrey, kMissingGrey, kMissingGrey};
    return viridis()[static_cast<std::size_t>(colour_index(value, range))];
}

std::string encode_map_tiff_float(std::span<const float> layer, std::size_t width,
                                  std::size_t height) {
    check_layer(layer.size(), width, height, kMaxTiffSide - 1, "map tiff");
    codec::TiffEncodeOptions options;
    options.mode = "wl";
    options.orientation = true;
    options.software = "roughscope map";
    return codec::encode_tiff({layer.data(), width, height, 1, {32, true}, 0}, options, "map tiff");
}

std::string encode_npy(std::span<const float> layer, std::size_t width, std::size_t height,
                       std::size_t channels) {
    if (channels == 0 || layer.size() % channels != 0)
        throw InvalidArgument(concat("npy: ", std::to_string(layer.size()),
                                     " values are not a whole number of ", std::to_string(channels),
                                     "-channel pixels"));
    check_layer(layer.size() / channels, width, height, kMaxTiffSide - 1, "npy");
    std::string header = concat("{'descr': '<f4', 'fortran_order': False, 'shape': (",
                                std::to_string(height), ", ", std::to_string(width),
                                channels > 1 ? concat(", ", std::to_string(channels)) : "", "), }");
    // magic (6) + version (2) + length (2) + header, padded with spaces, ended by '\n', to a
    // multiple of 64 bytes.
    const std::size_t total = (10 + header.size() + 1 + 63) / 64 * 64;
    header.append(total - 10 - header.size() - 1, ' ');
    header.push_back('\n');
    std::string out;
    out.reserve(total + layer.size() * 4);
    out.append("\x93NUMPY", 6);
    out.push_back('\x01');
    out.push_back('\x00');
    const auto length = static_cast<std::uint16_t>(header.size());
    out.push_back(static_cast<char>(length & 0xff));
    out.push_back(static_cast<char>(length >> 8));
    out.append(header);
    for (const float v : layer) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &v, 4);
        for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((bits >> (8 * b)) & 0xff));
    }
    return out;
}

std::string encode_map_png(std::span<const float> layer, std::size_t width, std::size_t height,
                           ColourRange range, const std::string& label) {
    check_layer(layer.size(), width, height, kMaxPngSide / 2, "map png");
    check_range(range);
    const int f = enlargement(width, height);
    const int mw = static_cast<int>(width) * f, mh = static_cast<int>(height) * f;
    const int panel = 90, footer = 22;
    const int canvas_h = std::max(mh, 200);
    cv::Mat rgb(canvas_h + footer, mw + panel, CV_8UC3, cv::Scalar(255, 255, 255));
    for (int r = 0; r < mh; ++r) {
        auto* out = rgb.ptr<cv::Vec3b>(r);
        const float* in = layer.data() + static_cast<std::size_t>(r / f) * width;
        for (int x = 0; x < mw; ++x) {
            const auto c = map_colour(in[x / f], range);
            out[x] = cv::Vec3b(c[0], c[1], c[2]);
        }
    }
    // The colour bar: upper at the top, lower at the bottom.
    const int y0 = 12, y1 = canvas_h - 12, bx0 = mw + 10, bx1 = mw + 28;
    for (int y = y0; y <= y1; ++y) {
        const double t = 1.0 - static_cast<double>(y - y0) / static_cast<double>(y1 - y0);
        const auto c = viridis()[static_cast<std::size_t>(std::lround(t * 255.0))];
        for (int x = bx0; x < bx1; ++x) rgb.at<cv::Vec3b>(y, x) = cv::Vec3b(c[0], c[1], c[2]);
    }
    cv::rectangle(rgb, cv::Point(bx0 - 1, y0 - 1), cv::Point(bx1, y1 + 1), cv::Scalar(0, 0, 0), 1);
    constexpr int kTicks = 5;
    for (int k = 0; k < kTicks; ++k) {
        const double t = static_cast<double>(k) / (kTicks - 1);
        const int y = y1 - static_cast<int>(std::lround(t * (y1 - y0)));
        cv::line(rgb, cv::Point(bx1, y), cv::Point(bx1 + 4, y), cv::Scalar(0, 0, 0), 1);
        put_text(rgb, tick_text(range.lower + t * (range.upper - range.lower)), bx1 + 6, y + 4);
    }
    put_text(rgb, label, 4, canvas_h + 15);
    return encode_rgb_png(rgb);
}

std::string encode_class_png(std::span<const std::uint8_t> classes, std::size_t width,
                             std::size_t height) {
    check_layer(classes.size(), width, height, kMaxPngSide / 2, "class png");
    const int f = enlargement(width, height);
    const int mw = static_cast<int>(width) * f, mh = static_cast<int>(height) * f;
    const int panel = 150;
    const int canvas_h = std::max(mh, 100);
    cv::Mat rgb(canvas_h, mw + panel, CV_8UC3, cv::Scalar(255, 255, 255));
    auto colour = [](std::uint8_t c) {
        if (c < 3) {
            const auto& k = kClassColours[c];
            return cv::Vec3b(k[0], k[1], k[2]);
        }
        return cv::Vec3b(kMissingGrey, kMissingGrey, kMissingGrey);
    };
    for (int r = 0; r < mh; ++r) {
        auto* out = rgb.ptr<cv::Vec3b>(r);
        const std::uint8_t* in = classes.data() + static_cast<std::size_t>(r / f) * width;
        for (int x = 0; x < mw; ++x) out[x] = colour(in[x / f]);
    }
    static constexpr std::array<const char*, 4> kNames{"slightly rough", "moderately rough",
                                                       "very rough", "none"};
    for (int k = 0; k < 4; ++k) {
        const int y = 10 + 22 * k;
        const cv::Vec3b c = colour(k < 3 ? static_cast<std::uint8_t>(k) : kClassNone);
        cv::rectangle(rgb, cv::Point(mw + 8, y), cv::Point(mw + 22, y + 14),
                      cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
        cv::rectangle(rgb, cv::Point(mw + 8, y), cv::Point(mw + 22, y + 14), cv::Scalar(0, 0, 0),
                      1);
        put_text(rgb, kNames[static_cast<std::size_t>(k)], mw + 28, y + 11);
    }
    return encode_rgb_png(rgb);
}

std::string encode_normals_png(std::span<const float> normals, std::size_t width,
                               std::size_t height) {
    if (normals.size() % 3 != 0)
        throw InvalidArgument("normals png: the values are not (n_x, n_y, n_z) triples");
    check_layer(normals.size() / 3, width, height, kMaxPngSide, "normals png");
    cv::Mat rgb(static_cast<int>(height), static_cast<int>(width), CV_8UC3,
                cv::Scalar(kMissingGrey, kMissingGrey, kMissingGrey));
    for (std::size_t r = 0; r < height; ++r) {
        auto* out = rgb.ptr<cv::Vec3b>(static_cast<int>(r));
        for (std::size_t x = 0; x < width; ++x) {
            const float* n = normals.data() + 3 * (r * width + x);
            if (!std::isfinite(n[0])) continue;
            for (int c = 0; c < 3; ++c)
                out[x][c] = static_cast<std::uint8_t>(
                    std::lround(std::clamp((n[c] + 1.0F) * 0.5F, 0.0F, 1.0F) * 255.0F));
        }
    }
    return encode_rgb_png(rgb);
}

}  // namespace roughscope::image
