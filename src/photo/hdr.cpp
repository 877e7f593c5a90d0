// Response recovery (OpenCV's photo module) and HDR merging (hdr.hpp).
#include "roughscope/photo/hdr.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/photo.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {
namespace {

// The codes an HDR merge trusts (merge_hdr).
constexpr std::uint8_t kWellExposedLow = 16;
constexpr std::uint8_t kWellExposedHigh = 239;

std::string name_of(const LinearImage& image, std::size_t k) {
    return image.info.source.empty() ? concat("bracket[", std::to_string(k), "]")
                                     : image.info.source;
}

// Throws unless `image` holds 8-bit codes (linear response, black level 0, white level 255).
void check_code_scale(const LinearImage& image, const std::string& name) {
    check_linear_image(image);
    const bool black_zero =
        std::all_of(image.info.black_level_dn.begin(), image.info.black_level_dn.end(),
                    [](double b) { return b == 0.0; });
    if (image.info.bits_per_sample != 8 || image.info.is_float ||
        image.info.response != Response::Linear || !black_zero ||
        image.info.white_level_dn != 255.0)
        throw InvalidArgument(
            concat(name,
                   ": a response curve needs 8-bit images read on the code scale (response "
                   "linear, black level 0, white level 255); this one has ",
                   std::to_string(image.info.bits_per_sample), " bits, response ",
                   to_string(image.info.response), ", white level ",
                   check::format_number(image.info.white_level_dn)));
}

void check_bracket(const std::vector<LinearImage>& bracket, const std::vector<double>& exposure_s) {
    if (bracket.size() < 2)
        throw InvalidArgument(concat("an exposure bracket needs at least 2 images, not ",
                                     std::to_string(bracket.size())));
    if (exposure_s.size() != bracket.size())
        throw InvalidArgument(concat("an exposure bracket of ", std::to_string(bracket.size()),
                                     " images needs as many exposure times, not ",
                                     std::to_string(exposure_s.size())));
    for (std::size_t k = 0; k < bracket.size(); ++k) {
        const std::string name = name_of(bracket[k], k);
        check_code_scale(bracket[k], name);
        if (!(exposure_s[k] > 0.0 && std::isfinite(exposure_s[k])))
            throw InvalidArgument(concat(name,
                                         ": exposure_s = ", check::format_number(exposure_s[k]),
                                         " must be finite and > 0"));
        if (bracket[k].width != bracket[0].width || bracket[k].height != bracket[0].height ||
            bracket[k].channels != bracket[0].channels)
            throw InvalidArgument(concat(name, " differs in size or channels from ",
                                         name_of(bracket[0], 0),
                                         ": a bracket is one scene from one camera position"));
    }
    const auto [lo, hi] = std::minmax_element(exposure_s.begin(), exposure_s.end());
    if (*lo == *hi)
        throw InvalidArgument(
            "the exposure times of a bracket must differ (the response is recovered from how a "
            "pixel's code changes with exposure)");
}

std::uint8_t code_of(float value) {
    return static_cast<std::uint8_t>(std::clamp(std::lround(value * 255.0F), 0L, 255L));
}

// Planar codes → an interleaved 8-bit Mat with the image's channels.
cv::Mat to_mat(const LinearImage& image) {
    const int channels = static_cast<int>(image.channels);
    cv::Mat mat(static_cast<int>(image.height), static_cast<int>(image.width),
                CV_MAKETYPE(CV_8U, channels));
    for (std::size_t r = 0; r < image.height; ++r) {
        auto* row = mat.ptr<std::uint8_t>(static_cast<int>(r));
        for (std::size_t x = 0; x < image.width; ++x)
            for (std::size_t c = 0; c < image.channels; ++c)
                row[x * image.channels + c] = code_of(image.value(c, r, x));
    }
    return mat;
}

void check_curve(const ResponseCurve& curve, std::size_t channels, const std::string& name) {
    if (curve.light.size() < channels)
        throw InvalidArgument(concat(name, " has ", std::to_string(channels),
                                     " channels but the response curve ",
                                     std::to_string(curve.light.size())));
    for (std::size_t c = 0; c < channels; ++c)
        for (const double x : curve.light[c])
            if (!(x >= 0.0 && std::isfinite(x)))
                throw InvalidArgument(concat("the response curve of channel ", std::to_string(c),
                                             " must be finite and ≥ 0 at every code"));
}

}  // namespace

ResponseCurve recover_response_debevec(const std::vector<LinearImage>& bracket,
                                       const std::vector<double>& exposure_s,
                                       const DebevecOptions& options) {
    check_bracket(bracket, exposure_s);
    if (options.samples <= 0)
        throw InvalidArgument(
            concat("samples = ", std::to_string(options.samples), " must be > 0"));
    if (!(options.smoothness > 0.0 && std::isfinite(options.smoothness)))
        throw InvalidArgument(concat("smoothness = ", check::format_number(options.smoothness),
                                     " must be finite and > 0"));
    std::vector<cv::Mat> images;
    images.reserve(bracket.size());
    for (const LinearImage& image : bracket) images.push_back(to_mat(image));
    std::vector<float> times;
    times.reserve(exposure_s.size());
    for (const double t : exposure_s) times.push_back(static_cast<float>(t));
    cv::Mat response;
    cv::createCalibrateDebevec(options.samples, static_cast<float>(options.smoothness), false)
        ->process(images, response, times);
    const std::size_t channels = bracket.front().channels;
    ResponseCurve curve;
    curve.light.resize(channels);
    for (std::size_t c = 0; c < channels; ++c) {
        const double top = response.ptr<float>(255)[c];
        for (int z = 0; z < 256; ++z) {
            const double x = response.ptr<float>(z)[c] / top;
            if (!(x > 0.0 && std::isfinite(x)))
                throw NoSolution(concat(
                    "the response curve of channel ", std::to_string(c),
                    " could not be recovered from the bracket (code ", std::to_string(z),
                    "): the exposures must overlap and the scene cover a range of brightness"));
            curve.light[c][static_cast<std::size_t>(z)] = x;
        }
    }
    return curve;
}

ResponseCurve response_curve_of(Response response, double gamma, std::size_t channels) {
    if (response == Response::Gamma && !(gamma > 0.0 && std::isfinite(gamma)))
        throw InvalidArgument(
            concat("gamma = ", check::format_number(gamma), " must be finite and > 0"));
    if (channels != 1 && channels != 3)
        throw InvalidArgument(concat("channels = ", std::to_string(channels), " must be 1 or 3"));
    std::array<double, 256> light{};
    for (std::size_t z = 0; z < 256; ++z) {
        const double u = static_cast<double>(z) / 255.0;
        light[z] = response == Response::Srgb    ? srgb_decode(u)
                   : response == Response::Gamma ? std::pow(u, gamma)
                                                 : u;
    }
    return ResponseCurve{std::vector<std::array<double, 256>>(channels, light)};
}

void apply_response_curve(LinearImage& image, const ResponseCurve& curve) {
    const std::string name = name_of(image, 0);
    check_code_scale(image, name);
    check_curve(curve, image.channels, name);
    const std::size_t n = image.pixel_count();
    for (std::size_t c = 0; c < image.channels; ++c) {
        float* v = image.values.data() + c * n;
        for (std::size_t i = 0; i < n; ++i)
            v[i] = static_cast<float>(curve.light[c][code_of(v[i])]);
    }
    image.info.warnings.push_back(
        concat(name, ": values through a response curve recovered from an exposure bracket"));
}

LinearImage merge_hdr(const std::vector<LinearImage>& bracket,
                      const std::vector<double>& exposure_s, const ResponseCurve& curve) {
    check_bracket(bracket, exposure_s);
    const LinearImage& first = bracket.front();
    check_curve(curve, first.channels, name_of(first, 0));
    // E = Σ_k w(z_k) X(z_k)/t_k / Σ_k w(z_k) with Debevec's hat weight w(z) = min(z, 255 − z)
    // restricted to the well-exposed codes [16, 239]: a clipped code never enters the mean, nor
    // one next to clipping, where the recovered curve is least certain (its calibration data mix
    // in clipped pixels). OpenCV's MergeDebevec weights every code but 0 and 255 alike with the
    // hat, which biases the brightest pixels by tens of percent.
    LinearImage out;
    out.width = first.width;
    out.height = first.height;
    out.channels = first.channels;
    out.info = first.info;
    out.info.exposure_s = 1.0;
    out.values.assign(first.values.size(), 0.0F);
    out.flags.assign(first.pixel_count(), 0);
    const std::size_t n = first.pixel_count();
    for (std::size_t c = 0; c < first.channels; ++c) {
        for (std::size_t i = 0; i < n; ++i) {
            double sum_w = 0.0, sum_wx = 0.0;
            bool any_high = false;
            for (std::size_t k = 0; k < bracket.size(); ++k) {
                const std::uint8_t z = code_of(bracket[k].values[c * n + i]);
                any_high = any_high || z >= 128;
                const double w = z >= kWellExposedLow && z <= kWellExposedHigh
                                     ? std::min(z, static_cast<std::uint8_t>(255 - z))
                                     : 0.0;
                sum_w += w;
                sum_wx += w * curve.light[c][z] / exposure_s[k];
            }
            if (sum_w > 0.0) {
                out.values[c * n + i] = static_cast<float>(sum_wx / sum_w);
            } else {  // clipped in every exposure: too bright or too dark for the whole bracket
                out.flags[i] |= any_high ? kPixelSaturated : kPixelClippedLow;
            }
        }
    }
    return out;
}

}  // namespace roughscope::image
