// Internal helper of the simulation topic: e^{iθ} for the phase factors exp(i v_z z) of the
// Kirchhoff sums, the hot loop of every realisation.
//
// θ is reduced to k·(2π/N) + r with k = round(θ N/2π), N = 4096, |r| ≤ π/N (Cody–Waite: 2π/N in
// two parts, so r carries no error beyond θ's own rounding); e^{iθ} = E[k mod N]·e^{ir} with E a
// table of correctly rounded cos, sin values and e^{ir} from its Taylor polynomials to r⁷
// (remainder below 1e-19). Agrees with std::cos/std::sin to a few 1e-16 (tests/cpp/simulation) at
// several times their speed, because the loop has no branch and no library call.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>

namespace roughscope::simulation::detail {

inline constexpr std::size_t kPhasorTableSize = 4096;

struct PhasorTable {
    std::array<double, kPhasorTableSize> cos_value{}, sin_value{};
    PhasorTable() {
        for (std::size_t k = 0; k < kPhasorTableSize; ++k) {
            const double a = 2.0 * 3.14159265358979323846 * static_cast<double>(k) /
                             static_cast<double>(kPhasorTableSize);
            cos_value[k] = std::cos(a);
            sin_value[k] = std::sin(a);
        }
    }
};

inline const PhasorTable& phasor_table() {
    static const PhasorTable table;
    return table;
}

// e^{iθ} for finite θ with |θ| ≤ 1e12 (beyond, the reduction loses the fraction of a turn; the
// callers' phases v_z·z are far below).
inline std::complex<double> unit_phasor(double theta, const PhasorTable& t) {
    constexpr double kStepsPerRadian =
        static_cast<double>(kPhasorTableSize) / (2.0 * 3.14159265358979323846);
    // 2π/N = kStepHi + kStepLo, kStepHi with 26 significant bits: k·kStepHi is exact for
    // |k| < 2^27 (|θ| < 2e5); beyond, its rounding is that of θ itself (~ulp(θ)).
    constexpr double kStepHi = 0.001533980801468715;
    constexpr double kStepLo = -1.3583073841960075e-11;
    // Round to nearest by the 1.5·2^52 shift (exact for |x| < 2^51, i.e. |θ| < 3.5e12; no
    // library call, unlike std::nearbyint on baseline x86-64).
    constexpr double kRoundShift = 6755399441055744.0;
    const double kf = (theta * kStepsPerRadian + kRoundShift) - kRoundShift;
    const double r = (theta - kf * kStepHi) - kf * kStepLo;
    const auto k = static_cast<std::int64_t>(kf);
    const std::size_t idx = static_cast<std::size_t>(k) & (kPhasorTableSize - 1);
    const double r2 = r * r;
    const double c = 1.0 - r2 * (0.5 - r2 * (1.0 / 24.0 - r2 * (1.0 / 720.0)));
    const double s = r * (1.0 - r2 * (1.0 / 6.0 - r2 * (1.0 / 120.0 - r2 * (1.0 / 5040.0))));
    const double tc = t.cos_value[idx], ts = t.sin_value[idx];
    return {tc * c - ts * s, ts * c + tc * s};
}

}  // namespace roughscope::simulation::detail
