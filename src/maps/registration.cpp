// Phase correlation of two photographs (image/registration.hpp, docs/maps.md "Registration").
#include "roughscope/maps/registration.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <complex>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "surface/fft.hpp"

namespace roughscope::image {
namespace {

namespace fft = surface::fft;

constexpr std::size_t kMinSidePx = 16;
constexpr std::ptrdiff_t kPeakExclusionRadius = 5;  // the peak's 11 × 11 neighbourhood

// The square root of the Hann window, h(i) = √(½ (1 − cos(2π i/(n − 1)))), i in [0, n): the
// separable window √(h_rows(r) h_cols(c)) of cv::createHanningWindow.
std::vector<double> sqrt_hann(std::size_t n) {
    std::vector<double> h(n);
    const double step = 2.0 * kPi / static_cast<double>(n - 1);
    for (std::size_t i = 0; i < n; ++i)
        h[i] = std::sqrt(0.5 * (1.0 - std::cos(step * static_cast<double>(i))));
    return h;
}

// The transform's real rows: the channel average of the crop [x0, x0 + w) × [y0, y0 + h) of
// `image`, its mean removed, times the window (the window's own shape would otherwise correlate
// at zero shift). The crop's values are the only ones read: a non-finite one is
// check_linear_image's InvalidArgument.
void load_windowed_crop(const LinearImage& image, std::size_t x0, std::size_t y0,
                        fft::RealToComplex& t) {
    const std::size_t h = t.rows(), w = t.cols();
    const double scale = 1.0 / static_cast<double>(image.channels);
    double sum = 0.0;
    for (std::size_t r = 0; r < h; ++r) {
        double* row = t.real_row(r);
        std::fill(row, row + w, 0.0);
        for (std::size_t c = 0; c < image.channels; ++c) {
            const float* src = image.plane(c) + (y0 + r) * image.width + x0;
            for (std::size_t x = 0; x < w; ++x) row[x] += scale * static_cast<double>(src[x]);
        }
        for (std::size_t x = 0; x < w; ++x) sum += row[x];
    }
    if (!std::isfinite(sum)) {
        for (std::size_t c = 0; c < image.channels; ++c)
            for (std::size_t r = 0; r < h; ++r)
                for (std::size_t x = 0; x < w; ++x) {
                    const std::size_t k = c * image.pixel_count() + (y0 + r) * image.width + x0 + x;
                    if (!std::isfinite(image.values[k])) throw_non_finite_value(image, k);
                }
    }
    const double mean = sum / static_cast<double>(w * h);
    const std::vector<double> h_rows = sqrt_hann(h), h_cols = sqrt_hann(w);
    for (std::size_t r = 0; r < h; ++r) {
        double* row = t.real_row(r);
        for (std::size_t x = 0; x < w; ++x) row[x] = (row[x] - mean) * (h_rows[r] * h_cols[x]);
    }
}

// The phase-correlation surface r = IDFT(A B*/|A B*|) (scaled: a perfect match peaks at 1), a
// view of a transform's real rows, and its largest value (the first in row-major order).
struct CorrelationSurface {
    const fft::RealToComplex* values = nullptr;  // index (x, y) is the lag (x, y), periodic
    std::ptrdiff_t rows = 0, cols = 0;
    std::ptrdiff_t peak_x = 0, peak_y = 0;
    double peak_value = 0.0;
    double at(std::ptrdiff_t r, std::ptrdiff_t x) const {
        return values->real_row(static_cast<std::size_t>(r))[x];
    }
};

CorrelationSurface find_peak(const fft::RealToComplex& surface) {
    CorrelationSurface s;
    s.values = &surface;
    s.rows = static_cast<std::ptrdiff_t>(surface.rows());
    s.cols = static_cast<std::ptrdiff_t>(surface.cols());
    s.peak_value = -std::numeric_limits<double>::infinity();
    for (std::ptrdiff_t r = 0; r < s.rows; ++r)
        for (std::ptrdiff_t x = 0; x < s.cols; ++x)
            if (s.at(r, x) > s.peak_value) {
                s.peak_value = s.at(r, x);
                s.peak_x = x;
                s.peak_y = r;
            }
    return s;
}

// The peak-to-sidelobe ratio: (peak − mean)/sd of r outside the peak's neighbourhood (periodic).
double peak_to_sidelobe(const CorrelationSurface& s) {
    double sum = 0.0, sum2 = 0.0, n = 0.0;
    for (std::ptrdiff_t r = 0; r < s.rows; ++r) {
        const std::ptrdiff_t dr = std::min(std::abs(r - s.peak_y), s.rows - std::abs(r - s.peak_y));
        for (std::ptrdiff_t x = 0; x < s.cols; ++x) {
            const std::ptrdiff_t dx =
                std::min(std::abs(x - s.peak_x), s.cols - std::abs(x - s.peak_x));
            if (dr <= kPeakExclusionRadius && dx <= kPeakExclusionRadius) continue;
            const double v = s.at(r, x);
            sum += v;
            sum2 += v * v;
            n += 1.0;
        }
    }
    if (n < 2.0) return 0.0;
    const double mean = sum / n;
    const double sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
    // A lone peak on an exactly flat floor (identical images) is the largest PSR there is.
    const double psr = sd > 0.0 ? (s.peak_value - mean) / sd : (s.peak_value > mean ? 1e6 : 0.0);
    return std::isfinite(psr) ? std::min(psr, 1e6) : 0.0;
}

// The lag of the peak to a fraction of a pixel, as cv::phaseCorrelate finds it on the same
// surface: the centroid of the 5 × 5 values around the largest (periodic), lags wrapped to
// (−size/2, size/2]; `response` = the sum of those values (phaseCorrelate's response).
Eigen::Vector2d peak_centroid(const CorrelationSurface& s, double& response) {
    double sum = 0.0, sx = 0.0, sy = 0.0;
    for (std::ptrdiff_t dy = -2; dy <= 2; ++dy) {
        const std::ptrdiff_t r = ((s.peak_y + dy) % s.rows + s.rows) % s.rows;
        for (std::ptrdiff_t dx = -2; dx <= 2; ++dx) {
            const double v = s.at(r, ((s.peak_x + dx) % s.cols + s.cols) % s.cols);
            sum += v;
            sx += static_cast<double>(dx) * v;
            sy += static_cast<double>(dy) * v;
        }
    }
    response = sum;
    const auto wrap = [](std::ptrdiff_t lag, std::ptrdiff_t size) {
        return static_cast<double>(lag > size / 2 ? lag - size : lag);
    };
    Eigen::Vector2d lag(wrap(s.peak_x, s.cols), wrap(s.peak_y, s.rows));
    if (sum != 0.0) lag += Eigen::Vector2d(sx / sum, sy / sum);
    return lag;
}

// The phase-correlation surface r(x, y) = Re Σ cross(v, u) exp(2πi (u x/W + v y/H)) on the
// grid x = cx + step·(i − n), y = cy + step·(j − n), i, j in [0, 2n], by two matrix products
// (the upsampled DFT of Guizar-Sicairos, Thurman & Fienup, Opt. Lett. 33, 156 (2008)) over the
// half spectrum u = 0 … W/2 that a real-to-complex transform keeps: cross is Hermitian, so the
// columns u and W − u add up to 2 Re of column u's terms (weight 2; 1 for u = 0 and u = W/2).
// Returns the position of its largest value: the grid point, moved by the vertex of the parabola
// through it and its two neighbours along x and along y when it is inside the grid (the surface
// is smooth on this scale: a fraction of a grid step).
using HalfSpectrum = Eigen::Map<
    const Eigen::Matrix<std::complex<double>, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;

Eigen::Vector2d refine_peak(const HalfSpectrum& cross, std::size_t width, double cx, double cy,
                            double step, int n) {
    const Eigen::Index H = cross.rows();
    const int m = 2 * n + 1;
    const auto W = static_cast<double>(width);
    Eigen::MatrixXcd ey(m, H), ex(m, cross.cols());
    for (int i = 0; i < m; ++i) {
        const double y = cy + step * (i - n);
        for (Eigen::Index k = 0; k < H; ++k) {
            const double f = static_cast<double>(k <= H / 2 ? k : k - H);
            ey(i, k) = std::polar(1.0, 2.0 * kPi * f * y / static_cast<double>(H));
        }
        const double x = cx + step * (i - n);
        for (Eigen::Index u = 0; u < cross.cols(); ++u) {
            const bool single = u == 0 || 2 * u == static_cast<Eigen::Index>(width);
            ex(i, u) = std::polar(single ? 1.0 : 2.0, 2.0 * kPi * static_cast<double>(u) * x / W);
        }
    }
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
    const std::size_t w = result.crop_width_px = std::min(a.width, options.max_side_px);
    const std::size_t h = result.crop_height_px = std::min(a.height, options.max_side_px);
    const std::size_t x0 = (a.width - w) / 2;
    const std::size_t y0 = (a.height - h) / 2;
    // Two in-place real-to-complex transforms (FFTW, fft.hpp): A and B, then the normalised
    // cross-power spectrum A B*/|A B*| in both — B's copy for refine_peak, A's transformed back
    // into the correlation surface.
    fft::RealToComplex ta(h, w, fft::Layout::plane), tb(h, w, fft::Layout::plane);
    load_windowed_crop(a, x0, y0, ta);
    load_windowed_crop(b, x0, y0, tb);
    ta.forward();
    tb.forward();
    for (std::size_t r = 0; r < h; ++r) {
        std::complex<double>* fa = ta.spectrum_row(r);
        std::complex<double>* fb = tb.spectrum_row(r);
        for (std::size_t u = 0; u < ta.spectrum_cols(); ++u) {
            const std::complex<double> z = fa[u] * std::conj(fb[u]);
            // (A product of two spectra of values in [0, 1e38] cannot overflow a double: no
            // need for std::abs's scaling, which costs several times more.)
            const double m = std::sqrt(z.real() * z.real() + z.imag() * z.imag());
            fa[u] = fb[u] = m > 0.0 ? z / m : std::complex<double>(0.0, 0.0);
        }
    }
    ta.backward();
    const double scale = 1.0 / static_cast<double>(w * h);
    for (std::size_t r = 0; r < h; ++r) {
        double* row = ta.real_row(r);
        for (std::size_t x = 0; x < w; ++x) row[x] *= scale;
    }
    const CorrelationSurface surface = find_peak(ta);
    result.peak_to_sidelobe = peak_to_sidelobe(surface);
    double response = 0.0;
    Eigen::Vector2d shift = -peak_centroid(surface, response);
    result.response = std::isfinite(response) ? std::clamp(response, 0.0, 1.0) : 0.0;
    // The 5 × 5 centroid is pulled toward whole pixels by up to ~0.3 px: the peak is located
    // again on the upsampled surface, ±0.6 px around it in steps of 0.1 px, to a fraction of the
    // step by the parabola through the best point and its neighbours (refine_peak). The surface
    // of A B* peaks at −shift.
    if (std::isfinite(shift.x()) && std::isfinite(shift.y())) {
        const HalfSpectrum cross(tb.spectrum_row(0), static_cast<Eigen::Index>(h),
                                 static_cast<Eigen::Index>(tb.spectrum_cols()));
        shift = -refine_peak(cross, w, -shift.x(), -shift.y(), 0.1, 6);
    }
    result.shift_x_px = shift.x();
    result.shift_y_px = shift.y();
    result.magnitude_px = std::hypot(shift.x(), shift.y());
    if (!std::isfinite(result.magnitude_px)) {
        result.shift_x_px = result.shift_y_px = result.magnitude_px = 0.0;
        result.response = 0.0;
        result.peak_to_sidelobe = 0.0;
    }
    return result;
}

}  // namespace roughscope::image
