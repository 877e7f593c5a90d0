// Phase correlation of two photographs (image/registration.hpp, docs/maps.md "Registration").
#include "roughscope/image/registration.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

constexpr std::size_t kMinSidePx = 16;
constexpr int kPeakExclusionRadius = 5;  // the peak's 11 × 11 neighbourhood

// The channel average of the crop [x0, x0 + w) × [y0, y0 + h), as CV_64F.
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
    return out;
}

// The normalised cross-power spectrum A B*/|A B*| of the windowed images (CV_64FC2, full).
cv::Mat cross_power(const cv::Mat& a, const cv::Mat& b, const cv::Mat& window) {
    cv::Mat fa, fb, cross;
    cv::dft(a.mul(window), fa, cv::DFT_COMPLEX_OUTPUT);
    cv::dft(b.mul(window), fb, cv::DFT_COMPLEX_OUTPUT);
    cv::mulSpectrums(fa, fb, cross, 0, true);
    for (int r = 0; r < cross.rows; ++r) {
        auto* row = cross.ptr<cv::Vec2d>(r);
        for (int x = 0; x < cross.cols; ++x) {
            const double m = std::hypot(row[x][0], row[x][1]);
            row[x] = m > 0.0 ? row[x] / m : cv::Vec2d(0.0, 0.0);
        }
    }
    return cross;
}

// The peak-to-sidelobe ratio of the phase-correlation surface r = IDFT(cross): (peak − mean)/sd
// of r outside the peak's neighbourhood (periodic).
double peak_to_sidelobe(const cv::Mat& cross) {
    cv::Mat surface;
    cv::idft(cross, surface, cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
    cv::Point peak;
    double peak_value = 0.0;
    cv::minMaxLoc(surface, nullptr, &peak_value, nullptr, &peak);
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
    const double psr = sd > 0.0 ? (peak_value - mean) / sd : 0.0;
    return std::isfinite(psr) ? std::min(psr, 1e6) : 0.0;
}

// The phase-correlation surface r(x, y) = Re Σ cross(v, u) exp(2πi (u x/W + v y/H)) on the
// grid x = cx + step·(i − n), y = cy + step·(j − n), i, j in [0, 2n], by two matrix products
// (the upsampled DFT of Guizar-Sicairos, Thurman & Fienup, Opt. Lett. 33, 156 (2008)). Returns
// the grid point of the largest value.
cv::Point2d refine_peak(const Eigen::MatrixXcd& cross, double cx, double cy, double step, int n) {
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
    return {cx + step * static_cast<double>(bi - n), cy + step * static_cast<double>(bj - n)};
}

}  // namespace

Registration estimate_misregistration(const LinearImage& a, const LinearImage& b,
                                      const RegistrationOptions& options) {
    check_linear_image(a);
    check_linear_image(b);
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
    const cv::Mat ma = channel_average(a, x0, y0, result.crop_width_px, result.crop_height_px);
    const cv::Mat mb = channel_average(b, x0, y0, result.crop_width_px, result.crop_height_px);
    // The means removed: the window's own shape would otherwise correlate at zero shift.
    const cv::Mat za = ma - cv::mean(ma)[0];
    cv::Mat zb = mb - cv::mean(mb)[0];
    cv::Mat window;
    cv::createHanningWindow(window, ma.size(), CV_64F);
    const cv::Mat cross = cross_power(za, zb, window);
    result.peak_to_sidelobe = peak_to_sidelobe(cross);
    double response = 0.0;
    cv::Point2d shift = cv::phaseCorrelate(za, zb, window, &response);
    result.response = std::isfinite(response) ? std::clamp(response, 0.0, 1.0) : 0.0;
    // phaseCorrelate's 5 × 5 centroid is pulled toward whole pixels by up to ~0.3 px: the peak is
    // located again on the upsampled surface, ±0.6 px around it in steps of 0.1 px, then ±0.1 px
    // in steps of 0.01 px. The surface of A B* peaks at −shift.
    if (std::isfinite(shift.x) && std::isfinite(shift.y)) {
        Eigen::MatrixXcd c(cross.rows, cross.cols);
        for (int r = 0; r < cross.rows; ++r) {
            const auto* row = cross.ptr<cv::Vec2d>(r);
            for (int x = 0; x < cross.cols; ++x) c(r, x) = {row[x][0], row[x][1]};
        }
        cv::Point2d p = refine_peak(c, -shift.x, -shift.y, 0.1, 6);
        p = refine_peak(c, p.x, p.y, 0.01, 10);
        shift = -p;
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
