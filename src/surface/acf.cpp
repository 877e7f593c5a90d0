// Autocorrelation along rows and columns (paper §3.1: C_j with the N − j "unbiased" and the N
// "biased" normalisation), the 1/e correlation length and the Gaussian/exponential ACF fits.
// The lag sums are computed per line by zero-padded FFT (no wrap-around), O(N log N) a line;
// missing points are zeros in the data and in a mask whose autocorrelation counts the pairs.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "acf_lines.hpp"
#include "fft_rows.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface {
namespace detail {

namespace {
const double kInvE = std::exp(-1.0);
}

double acf_value(const std::vector<double>& sums, const std::vector<double>& pairs, std::size_t j,
                 AcfEstimator estimator) {
    if (pairs[j] <= 0 || pairs[0] <= 0 || sums[0] <= 0)
        return std::numeric_limits<double>::quiet_NaN();
    if (estimator == AcfEstimator::Biased) return sums[j] / sums[0];
    return (sums[j] / pairs[j]) / (sums[0] / pairs[0]);
}

std::optional<double> crossing_1e_samples(const double* sums, const double* pairs, std::size_t n,
                                          AcfEstimator estimator) {
    if (n == 0 || !(sums[0] > 0)) return std::nullopt;
    const auto pair_count = [&](std::size_t j) {
        return pairs != nullptr ? pairs[j] : static_cast<double>(n - j);
    };
    const double mean_square = sums[0] / pair_count(0);
    double prev_lag = 0;
    double prev_c = 1;
    for (std::size_t j = 1; j < n; ++j) {
        const double count = pair_count(j);
        if (count <= 0) continue;
        const double c =
            estimator == AcfEstimator::Biased ? sums[j] / sums[0] : sums[j] / count / mean_square;
        const auto lag = static_cast<double>(j);
        if (c <= kInvE) return prev_lag + (prev_c - kInvE) / (prev_c - c) * (lag - prev_lag);
        prev_lag = lag;
        prev_c = c;
    }
    return std::nullopt;
}

std::optional<double> crossing_1e_samples(const std::vector<double>& sums,
                                          const std::vector<double>& pairs,
                                          AcfEstimator estimator) {
    return crossing_1e_samples(sums.data(), pairs.data(), std::min(sums.size(), pairs.size()),
                               estimator);
}

LineAcf::LineAcf(std::size_t length, AcfEstimator estimator, bool per_line)
    : sums(length, 0.0),
      pairs(length, 0.0),
      length_(length),
      estimator_(estimator),
      per_line_(per_line),
      fft_(std::make_unique<RowFft>(fft::good_size(2 * length - 1))) {
    if (per_line_) {
        line_sums_.assign(length, 0.0);
        line_pairs_.assign(length, 0.0);
    }
}

LineAcf::~LineAcf() = default;

void LineAcf::add(const double* z) {
    double* r = fft_->real();
    const std::size_t nfft = fft_->nfft();
    const double inv = 1.0 / static_cast<double>(nfft);
    bool missing = false;
    double sum_sq = 0;
    std::size_t valid = 0;
    for (std::size_t k = 0; k < length_; ++k) {
        const double v = z[k];
        if (std::isnan(v)) {
            r[k] = 0;
            missing = true;
        } else {
            r[k] = v;
            sum_sq += v * v;
            ++valid;
        }
    }
    if (valid == 0) return;
    std::fill(r + length_, r + nfft, 0.0);
    fft_->autocorrelate_in_place();
    for (std::size_t j = 0; j < length_; ++j) sums[j] += r[j] * inv;
    if (!missing) {
        ++full_lines_;
        if (per_line_) record_line(sum_sq, valid, r, nullptr);  // the 1/e crossing is scale-free
        return;
    }
    if (per_line_) std::copy(r, r + length_, line_sums_.begin());
    for (std::size_t k = 0; k < length_; ++k) r[k] = std::isnan(z[k]) ? 0.0 : 1.0;
    std::fill(r + length_, r + nfft, 0.0);
    fft_->autocorrelate_in_place();
    for (std::size_t j = 0; j < length_; ++j) {
        const double count = std::round(r[j] * inv);  // an integer up to FFT round-off
        pairs[j] += count;
        if (per_line_) line_pairs_[j] = count;
    }
    if (per_line_) record_line(sum_sq, valid, line_sums_.data(), line_pairs_.data());
}

void LineAcf::record_line(double sum_sq, std::size_t valid, const double* line_sums,
                          const double* line_pairs) {
    line_rms_um.push_back(std::sqrt(sum_sq / static_cast<double>(valid)));
    if (sum_sq <= 0) return;
    if (const auto crossing = crossing_1e_samples(line_sums, line_pairs, length_, estimator_))
        line_crossing.push_back(*crossing);
    else
        ++lines_without_crossing;
}

void LineAcf::finish() {
    for (std::size_t j = 0; j < length_; ++j)
        pairs[j] += static_cast<double>(full_lines_) * static_cast<double>(length_ - j);
    full_lines_ = 0;
}

void accumulate_rows(const HeightMap& map, LineAcf& acc) {
    for (std::size_t iy = 0; iy < map.ny; ++iy) acc.add(&map.heights_um[iy * map.nx]);
}

void accumulate_columns(const HeightMap& map, LineAcf& acc) {
    // Columns are gathered a block at a time into contiguous lines (row segments are read
    // contiguously), then handled as rows.
    // The block's lines are padded to a stride that is not a multiple of a cache line set's
    // span, so the write streams do not evict each other.
    constexpr std::size_t kBlock = 64;
    constexpr std::size_t kAhead = 8;
    const std::size_t stride = map.ny + 8;
    std::vector<double> block(kBlock * stride);
    for (std::size_t c0 = 0; c0 < map.nx; c0 += kBlock) {
        const std::size_t width = std::min(kBlock, map.nx - c0);
        for (std::size_t iy = 0; iy < map.ny; ++iy) {
            const double* row = &map.heights_um[iy * map.nx + c0];
            // The hardware prefetcher does not follow a row-sized stride: fetch rows ahead.
            if (iy + kAhead < map.ny)
                for (std::size_t k = 0; k < width; k += 8)
                    __builtin_prefetch(row + kAhead * map.nx + k);
            for (std::size_t k = 0; k < width; ++k) block[k * stride + iy] = row[k];
        }
        for (std::size_t k = 0; k < width; ++k) acc.add(&block[k * stride]);
    }
}

Curve acf_curve(const LineAcf& acc, AcfEstimator estimator, double spacing_um) {
    Curve curve;
    if (acc.sums.empty() || !(acc.sums[0] > 0)) return curve;
    for (std::size_t j = 0; j < acc.sums.size(); ++j) {
        const double c = acf_value(acc.sums, acc.pairs, j, estimator);
        if (std::isnan(c)) continue;
        curve.x.push_back(static_cast<double>(j) * spacing_um);
        curve.y.push_back(c);
    }
    return curve;
}

}  // namespace detail

Curve acf_along_x(const HeightMap& levelled, AcfEstimator estimator) {
    validate(levelled, "heights");
    detail::LineAcf acc(levelled.nx, estimator, false);
    detail::accumulate_rows(levelled, acc);
    acc.finish();
    return detail::acf_curve(acc, estimator, levelled.dx_um);
}

Curve acf_along_y(const HeightMap& levelled, AcfEstimator estimator) {
    validate(levelled, "heights");
    if (levelled.is_profile()) return {};
    detail::LineAcf acc(levelled.ny, estimator, false);
    detail::accumulate_columns(levelled, acc);
    acc.finish();
    return detail::acf_curve(acc, estimator, levelled.dy_um);
}

std::optional<double> correlation_length_1e(const Curve& acf) {
    const double inv_e = std::exp(-1.0);
    const std::size_t n = std::min(acf.x.size(), acf.y.size());
    for (std::size_t j = 1; j < n; ++j) {
        if (acf.y[j] > inv_e) continue;
        const double c0 = acf.y[j - 1];
        const double c1 = acf.y[j];
        if (!(c0 > inv_e)) return acf.x[j - 1];  // first point already below (not normalised)
        return acf.x[j - 1] + (c0 - inv_e) / (c0 - c1) * (acf.x[j] - acf.x[j - 1]);
    }
    return std::nullopt;
}

double acf_model(Correlation model, double lag_um, double T_um) {
    return acf(model, std::abs(lag_um) / T_um);
}

namespace {

double residual_sum(const std::vector<double>& x, const std::vector<double>& y, Correlation model,
                    double T) {
    double rss = 0;
    for (std::size_t j = 0; j < x.size(); ++j) {
        const double d = y[j] - acf_model(model, x[j], T);
        rss += d * d;
    }
    return rss;
}

// T minimising the residual sum: a scan over log T from x_max/100 to 100 x_max, then golden-
// section search in log T between the neighbours of the best scan point.
double fit_T(const std::vector<double>& x, const std::vector<double>& y, Correlation model) {
    const double x_max = *std::max_element(x.begin(), x.end());
    const double lo = std::log(x_max / 100.0);
    const double hi = std::log(x_max * 100.0);
    constexpr int kScan = 161;
    const double step = (hi - lo) / (kScan - 1);
    int best = 0;
    double best_rss = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kScan; ++i) {
        const double rss = residual_sum(x, y, model, std::exp(lo + step * i));
        if (rss < best_rss) {
            best_rss = rss;
            best = i;
        }
    }
    double a = lo + step * std::max(best - 1, 0);
    double b = lo + step * std::min(best + 1, kScan - 1);
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    double c = b - g * (b - a);
    double d = a + g * (b - a);
    double fc = residual_sum(x, y, model, std::exp(c));
    double fd = residual_sum(x, y, model, std::exp(d));
    for (int it = 0; it < 80 && b - a > 1e-12; ++it) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = residual_sum(x, y, model, std::exp(c));
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = residual_sum(x, y, model, std::exp(d));
        }
    }
    return std::exp(0.5 * (a + b));
}

}  // namespace

AcfModelFit fit_acf_models(const Curve& acf, double max_lag_um) {
    if (acf.x.size() != acf.y.size())
        throw InvalidArgument(concat("fit_acf_models: the ACF has ", std::to_string(acf.x.size()),
                                     " lags but ", std::to_string(acf.y.size()), " values"));
    check::positive("max_lag_um", max_lag_um, "µm");
    AcfModelFit fit;
    std::vector<double> x, y;
    for (std::size_t j = 0; j < acf.x.size(); ++j)
        if (std::abs(acf.x[j]) <= max_lag_um && std::isfinite(acf.y[j])) {
            x.push_back(std::abs(acf.x[j]));
            y.push_back(acf.y[j]);
        }
    fit.points = x.size();
    if (x.size() < 3 || !(*std::max_element(x.begin(), x.end()) > 0)) return fit;
    const double n = static_cast<double>(x.size());
    const auto aic = [n](double rss) {
        constexpr int kParameters = 1;
        return n * std::log(std::max(rss, 1e-300) / n) + 2.0 * kParameters;
    };
    for (const Correlation c : kCorrelations) {
        const double T = fit_T(x, y, c);
        fit.T_um[c] = T;
        fit.aic[c] = aic(residual_sum(x, y, c, T));
        if (!fit.better || fit.aic[c] < fit.aic[*fit.better]) fit.better = c;
    }
    return fit;
}

}  // namespace roughscope::surface
