// The shape of a measured ACF beyond its 1/e crossing: the variance of the ACF estimator
// (Bartlett's formula over the 2-D lags of the central lobe) that gives the standard error of T,
// and the negative swing and return of a periodic surface. Formulas: docs/surface.md,
// "Uncertainties" and "Periodic surfaces".
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "acf_lines.hpp"
#include "roughscope/surface/spectral.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface::detail {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

double curve_value(const Curve& acf, double lag_um) {
    const std::size_t n = std::min(acf.x.size(), acf.y.size());
    if (n == 0 || lag_um < acf.x.front() || lag_um > acf.x[n - 1]) return kNaN;
    const auto it =
        std::lower_bound(acf.x.begin(), acf.x.begin() + static_cast<std::ptrdiff_t>(n), lag_um);
    const auto i = static_cast<std::size_t>(it - acf.x.begin());
    if (acf.x[i] == lag_um || i == 0) return acf.y[i];
    const double t = (lag_um - acf.x[i - 1]) / (acf.x[i] - acf.x[i - 1]);
    return acf.y[i - 1] + t * (acf.y[i] - acf.y[i - 1]);
}

std::size_t central_lobe_samples(const Curve& acf, double spacing_um, std::optional<double> T_um,
                                 double lobe_over_T) {
    const std::size_t n = std::min(acf.x.size(), acf.y.size());
    if (n == 0) return 0;
    std::size_t last = static_cast<std::size_t>(std::llround(acf.x[n - 1] / spacing_um));
    for (std::size_t i = 1; i < n; ++i)
        if (acf.y[i] <= 0) {
            last = static_cast<std::size_t>(std::llround(acf.x[i - 1] / spacing_um));
            break;
        }
    if (T_um) {
        const double cap = std::ceil(lobe_over_T * *T_um / spacing_um);
        if (static_cast<double>(last) > cap) last = static_cast<std::size_t>(cap);
    }
    return last;
}

Acf2d profile_lag_grid(const Curve& acf, double spacing_um) {
    const std::size_t n = std::min(acf.x.size(), acf.y.size());
    std::size_t longest = 0;
    for (std::size_t i = 0; i < n; ++i)
        longest = std::max(longest, static_cast<std::size_t>(std::llround(acf.x[i] / spacing_um)));
    Acf2d grid;
    grid.nx = 2 * longest + 1;
    grid.ny = 1;
    grid.dx_um = spacing_um;
    grid.dy_um = spacing_um;
    grid.values.assign(grid.nx, kNaN);
    for (std::size_t i = 0; i < n; ++i) {
        const auto j = static_cast<std::size_t>(std::llround(acf.x[i] / spacing_um));
        grid.values[longest + j] = acf.y[i];
        grid.values[longest - j] = acf.y[i];
    }
    return grid;
}

BartlettSums bartlett_sums(const Acf2d& rho, std::size_t window_x, std::size_t window_y,
                           std::size_t shift_x, double rho_shift) {
    const auto half_x = static_cast<std::ptrdiff_t>(rho.nx / 2);
    const auto half_y = static_cast<std::ptrdiff_t>(rho.ny / 2);
    const auto wx = std::min(static_cast<std::ptrdiff_t>(window_x), half_x);
    const auto wy = std::min(static_cast<std::ptrdiff_t>(window_y), half_y);
    const auto h = static_cast<std::ptrdiff_t>(shift_x);
    // ρ inside the window (0 outside it and where no pair of points exists).
    const auto at = [&](std::ptrdiff_t jx, std::ptrdiff_t jy) {
        if (jx < -wx || jx > wx || jy < -wy || jy > wy) return 0.0;
        const double c = rho.at_lag(jx, jy);
        return std::isnan(c) ? 0.0 : c;
    };
    // A region of nx × ny points holds (nx − |Δx|)(ny − |Δy|) pairs Δ apart: the weights of the
    // finite-region sum (they matter for a map of few rows).
    const auto size_x = static_cast<double>(half_x + 1);
    const auto size_y = static_cast<double>(half_y + 1);
    BartlettSums out;
    for (std::ptrdiff_t jy = -wy; jy <= wy; ++jy) {
        const double weight_y = 1.0 - static_cast<double>(std::abs(jy)) / size_y;
        for (std::ptrdiff_t jx = -wx; jx <= wx; ++jx) {
            const double weight = weight_y * (1.0 - static_cast<double>(std::abs(jx)) / size_x);
            const double c = at(jx, jy);
            const double behind = at(jx - h, jy);
            out.s0 += weight * c * c;
            out.sh += weight * (c * c + at(jx + h, jy) * behind - 4.0 * rho_shift * c * behind +
                                2.0 * rho_shift * rho_shift * c * c);
        }
    }
    return out;
}

std::optional<AcfSwing> find_period(const Curve& acf, double max_lag_um, double threshold) {
    const std::size_t n = std::min(acf.x.size(), acf.y.size());
    // The first zero crossing τ0; the minimum over [τ0, 3 τ0] (a cosine's is at 2 τ0, half the
    // period); the maximum over [1.5, 2.5] × the minimum's lag (a cosine's is at twice it), which
    // must be an interior maximum. Both beyond ±threshold.
    std::size_t i = 1;
    while (i < n && acf.y[i] > 0) ++i;
    if (i >= n) return std::nullopt;
    const double zero_lag = acf.x[i];
    AcfSwing swing;
    swing.low = acf.y[i];
    swing.low_lag_um = zero_lag;
    for (; i < n && acf.x[i] <= std::min(3.0 * zero_lag, max_lag_um); ++i)
        if (acf.y[i] < swing.low) {
            swing.low = acf.y[i];
            swing.low_lag_um = acf.x[i];
        }
    if (!(swing.low <= -threshold)) return std::nullopt;
    const double from = 1.5 * swing.low_lag_um;
    const double to = std::min(2.5 * swing.low_lag_um, max_lag_um);
    std::optional<std::size_t> top;
    std::size_t first = n, last = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (acf.x[k] < from || acf.x[k] > to) continue;
        first = std::min(first, k);
        last = k;
        if (!top || acf.y[k] > acf.y[*top]) top = k;
    }
    if (!top || *top == first || *top == last || !(acf.y[*top] >= threshold)) return std::nullopt;
    const std::size_t t = *top;
    swing.high = acf.y[t];
    swing.period_um = acf.x[t];
    // Parabola through the maximum and its neighbours (equally spaced lags).
    const double a = acf.y[t - 1], b = acf.y[t], c = acf.y[t + 1];
    const double step = acf.x[t + 1] - acf.x[t];
    const double denom = a - 2 * b + c;
    if (denom < 0 && std::abs(acf.x[t] - acf.x[t - 1] - step) < 1e-9 * step)
        swing.period_um += 0.5 * (a - c) / denom * step;
    return swing;
}

}  // namespace roughscope::surface::detail
