// Phase correlation of two photographs (image/registration.hpp, docs/maps.md "Registration").
#include "roughscope/image/registration.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

constexpr std::size_t kMinSidePx = 16;
constexpr int kPeakExclusionRadius = 5;  // the peak's 11 × 11 neighbourhood

// The channel average of the crop [x0, x0 + w) × [y0, y0 + h), as CV_64F. The crop's values are
// the only ones read: a non-finite one is check_linear_image's InvalidArgument.
cv::Mat channel_average(const LinearImage& image, std::size_t x0, std::size_t y0, std::size_t w,
                        std::size_t h) {
    cv::Mat out(static_cast<int>(h), static_cast<int>(w), CV_64F, cv::Scalar(0.0));
    const double scale = 1.0 / static_cast<double>(image.channels);
    for (std::size_t c = 0; c < image.channels; ++c) {
        const float* plane = image.plane(c);
        for (std::size_t r = 0; r < h; ++r) {
            auto* row = out.ptr<double>(static_cast<int>(r));
            const float* src = plane + (y0 + r) * image.width + x0;
            for (std::size_t x = 0; x < w; ++x) row[x] += scale * static_cast<double>(src[x]);
        }
    }
    if (!std::isfinite(cv::sum(out)[0])) {
        for (std::size_t c = 0; c < image.channels; ++c)
            for (std::size_t r = 0; r < h; ++r)
                for (std::size_t x = 0; x < w; ++x) {
                    const std::size_t k = c * image.pixel_count() + (y0 + r) * image.width + x0 + x;
                    if (!std::isfinite(image.values[k])) throw_non_finite_value(image, k);
                }
    }
    return out;
}

// The crop with its mean removed (the window's own shape would otherwise correlate at zero
// shift), times the window w(r, c) = √(h_rows(r) · h_cols(c)), h_n(i) = ½ (1 − cos(2π i/(n − 1)))
// (cv::createHanningWindow's: the square root of the separable Hann window), in place.
void remove_mean_and_window(cv::Mat& crop) {
    const double mean = cv::mean(crop)[0];
    const auto hann = [](int n) {
        std::vector<double> h(static_cast<std::size_t>(n));
        const double step = 2.0 * kPi / (n - 1);
        for (int i = 0; i < n; ++i)
            h[static_cast<std::size_t>(i)] = std::sqrt(0.5 * (1.0 - std::cos(step * i)));
        return h;
    };
    const std::vector<double> h_rows = hann(crop.rows), h_cols = hann(crop.cols);
    for (int r = 0; r < crop.rows; ++r) {
        auto* row = crop.ptr<double>(r);
        for (int c = 0; c < crop.cols; ++c)
            row[c] = (row[c] - mean) *
                     (h_rows[static_cast<std::size_t>(r)] * h_cols[static_cast<std::size_t>(c)]);
    }
}

// The normalised cross-power spectrum A B*/|A B*| of the windowed crops (CV_64FC2, full); `a`
// and `b` are used as work space.
cv::Mat cross_power(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat fa, fb, cross;
    cv::dft(a, fa, cv::DFT_COMPLEX_OUTPUT);
    cv::dft(b, fb, cv::DFT_COMPLEX_OUTPUT);
    cv::mulSpectrums(fa, fb, cross, 0, true);
    fa.release();
    fb.release();
    for (int r = 0; r < cross.rows; ++r) {
        auto* row = cross.ptr<cv::Vec2d>(r);
        for (int x = 0; x < cross.cols; ++x) {
            // (A product of two spectra of values in [0, 1e38] cannot overflow a double: no
            // need for std::hypot's scaling, which costs several times more.)
            const double m = std::sqrt(row[x][0] * row[x][0] + row[x][1] * row[x][1]);
            row[x] = m > 0.0 ? row[x] / m : cv::Vec2d(0.0, 0.0);
        }
    }
    return cross;
}

// The phase-correlation surface r = IDFT(cross) (scaled: a perfect match peaks at 1) and its
// largest value.
struct CorrelationSurface {
    cv::Mat values;  // CV_64F; index (x, y) is the lag (x, y), periodic
    cv::Point peak;
    double peak_value = 0.0;
};

CorrelationSurface correlation_surface(const cv::Mat& cross) {
    CorrelationSurface s;
    cv::idft(cross, s.values, cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    cv::minMaxLoc(s.values, nullptr, &s.peak_value, nullptr, &s.peak);
    return s;
}

// The peak-to-sidelobe ratio: (peak − mean)/sd of r outside the peak's neighbourhood (periodic).
double peak_to_sidelobe(const CorrelationSurface& s) {
    const cv::Mat& surface = s.values;
    const cv::Point peak = s.peak;
    double sum = 0.0, sum2 = 0.0, n = 0.0;
    for (int r = 0; r < surface.rows; ++r) {
        const int dr = std::min(std::abs(r - peak.y), surface.rows - std::abs(r - peak.y));
        const auto* row = surface.ptr<double>(r);
        for (int x = 0; x < surface.cols; ++x) {
            const int dx = std::min(std::abs(x - peak.x), surface.cols - std::abs(x - peak.x));
            if (dr <= kPeakExclusionRadius && dx <= kPeakExclusionRadius) continue;
            sum += row[x];
            sum2 += row[x] * row[x];
            n += 1.0;
        }
    }
    if (n < 2.0) return 0.0;
    const double mean = sum / n;
    const double sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
    const double psr = sd > 0.0 ? (s.peak_value - mean) / sd : 0.0;
    return std::isfinite(psr) ? std::min(psr, 1e6) : 0.0;
}

// The lag of the peak to a fraction of a pixel, as cv::phaseCorrelate finds it on the same
// surface: the centroid of the 5 × 5 values around the largest (periodic), lags wrapped to
// (−size/2, size/2]; `response` = the sum of those values (phaseCorrelate's response).
cv::Point2d peak_centroid(const CorrelationSurface& s, double& response) {
    const cv::Mat& surface = s.values;
    double sum = 0.0, sx = 0.0, sy = 0.0;
    for (int dy = -2; dy <= 2; ++dy) {
        const int r = ((s.peak.y + dy) % surface.rows + surface.rows) % surface.rows;
        const auto* row = surface.ptr<double>(r);
        for (int dx = -2; dx <= 2; ++dx) {
            const double v = row[((s.peak.x + dx) % surface.cols + surface.cols) % surface.cols];
            sum += v;
            sx += dx * v;
            sy += dy * v;
        }
    }
    response = sum;
    const auto wrap = [](int lag, int size) { return lag > size / 2 ? lag - size : lag; };
    cv::Point2d lag(wrap(s.peak.x, surface.cols), wrap(s.peak.y, surface.rows));
    if (sum != 0.0) lag += cv::Point2d(sx / sum, sy / sum);
    return lag;
}

// The phase-correlation surface r(x, y) = Re Σ cross(v, u) exp(2πi (u x/W + v y/H)) on the
// grid x = cx + step·(i − n), y = cy + step·(j − n), i, j in [0, 2n], by two matrix products
// (the upsampled DFT of Guizar-Sicairos, Thurman & Fienup, Opt. Lett. 33, 156 (2008)). Returns
// the position of its largest value: the grid point, moved by the vertex of the parabola through
// it and its two neighbours along x and along y when it is inside the grid (the surface is smooth
// on this scale: a fraction of a grid step).
using RowMajorComplex = Eigen::Map<
    const Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

cv::Point2d refine_peak(const RowMajorComplex& cross, double cx, double cy, double step, int n) {
    const Eigen::Index H = cross.rows(), W = cross.cols();
    const int m = 2 * n + 1;
    auto kernel = [&](Eigen::Index size, double centre) {
        Eigen::MatrixXcd e(m, size);
        for (int i = 0; i < m; ++i) {
            const double pos = centre + step * (i - n);
            for (Eigen::Index k = 0; k < size; ++k) {
                const double f = static_cast<double>(k <= size / 2 ? k : k - size);
                const double phase = 2.0 * kPi * f * pos / static_cast<double>(size);
                e(i, k) = std::complex<double>(std::cos(phase), std::sin(phase));
            }
        }
        return e;
    };
    const Eigen::MatrixXcd ey = kernel(H, cy), ex = kernel(W, cx);
    const Eigen::MatrixXd r = (ey * cross * ex.transpose()).real();
    Eigen::Index bi = 0, bj = 0;
    r.maxCoeff(&bj, &bi);
    // The vertex of the parabola through three equally spaced values, in steps from the middle.
    const auto vertex = [](double before, double at, double after) {
        const double curvature = before - 2.0 * at + after;
        if (!(curvature < 0.0)) return 0.0;
        return std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
    };
    double di = 0.0, dj = 0.0;
    if (bi > 0 && bi + 1 < m) di = vertex(r(bj, bi - 1), r(bj, bi), r(bj, bi + 1));
    if (bj > 0 && bj + 1 < m) dj = vertex(r(bj - 1, bi), r(bj, bi), r(bj + 1, bi));
    return {cx + step * (static_cast<double>(bi - n) + di),
            cy + step * (static_cast<double>(bj - n) + dj)};
}

}  // namespace

Registration estimate_misregistration(const LinearImage& a, const LinearImage& b,
                                      const RegistrationOptions& options) {
    check_linear_image_layout(a);
    check_linear_image_layout(b);
    if (a.width != b.width || a.height != b.height || a.channels != b.channels)
        throw InvalidArgument(concat(
            "registration: ", b.info.source, " is ", std::to_string(b.width), " x ",
            std::to_string(b.height), " x ", std::to_string(b.channels), " but ", a.info.source,
            " is ", std::to_string(a.width), " x ", std::to_string(a.height), " x ",
            std::to_string(a.channels), ": the two images must have the same size and channels"));
    if (options.max_side_px < kMinSidePx)
        throw InvalidArgument(
            concat("registration: max_side_px = ", std::to_string(options.max_side_px),
                   " must be at least ", std::to_string(kMinSidePx)));
    if (a.width < kMinSidePx || a.height < kMinSidePx)
        throw InvalidArgument(concat("registration: the images are ", std::to_string(a.width),
                                     " x ", std::to_string(a.height),
                                     " pixels; phase correlation needs at least ",
                                     std::to_string(kMinSidePx), " on each side"));
    Registration result;
    result.crop_width_px = std::min(a.width, options.max_side_px);
    result.crop_height_px = std::min(a.height, options.max_side_px);
    const std::size_t x0 = (a.width - result.crop_width_px) / 2;
    const std::size_t y0 = (a.height - result.crop_height_px) / 2;
    cv::Mat ma = channel_average(a, x0, y0, result.crop_width_px, result.crop_height_px);
    cv::Mat mb = channel_average(b, x0, y0, result.crop_width_px, result.crop_height_px);
    remove_mean_and_window(ma);
    remove_mean_and_window(mb);
    const cv::Mat cross = cross_power(ma, mb);
    // One inverse transform serves the peak-to-sidelobe ratio and the peak (the three transforms
    // cv::phaseCorrelate would repeat on the same windowed images are not needed).
    const CorrelationSurface surface = correlation_surface(cross);
    result.peak_to_sidelobe = peak_to_sidelobe(surface);
    double response = 0.0;
    cv::Point2d shift = -peak_centroid(surface, response);
    result.response = std::isfinite(response) ? std::clamp(response, 0.0, 1.0) : 0.0;
    // The 5 × 5 centroid is pulled toward whole pixels by up to ~0.3 px: the peak is located
    // again on the upsampled surface, ±0.6 px around it in steps of 0.1 px, to a fraction of the
    // step by the parabola through the best point and its neighbours (refine_peak). The surface
    // of A B* peaks at −shift.
    if (std::isfinite(shift.x) && std::isfinite(shift.y)) {
        // The spectrum in place (cv::Vec2d and std::complex<double> are both re, im).
        assert(cross.isContinuous());
        const RowMajorComplex c(reinterpret_cast<const std::complex<double>*>(cross.ptr()),
                                cross.rows, cross.cols);
        shift = -refine_peak(c, -shift.x, -shift.y, 0.1, 6);
    }
    result.shift_x_px = shift.x;
    result.shift_y_px = shift.y;
    result.magnitude_px = std::hypot(shift.x, shift.y);
    if (!std::isfinite(result.magnitude_px)) {
        result.shift_x_px = result.shift_y_px = result.magnitude_px = 0.0;
        result.response = 0.0;
        result.peak_to_sidelobe = 0.0;
    }
    return result;
}

}  // namespace roughscope::image
