// The batch very-rough brightness (scattering/brightness_batch.hpp) against the scalar
// very_rough_brightness (Eq. 4 / Eq. 5, beckmann.hpp), on every instruction set the CPU has.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/brightness_batch.hpp"
#include "roughscope/scattering/geometry.hpp"

using namespace roughscope;

namespace {

// Largest relative difference the batch kernel may have from the scalar function (documented in
// brightness_batch.hpp).
constexpr double kTolerance = 1e-12;

struct Sample {
    std::vector<double> ti, ts, ps, m;
};

// Random geometries: θ in [0, 89°], φs over a few turns either side (some far out), σ/T in
// [0.1, 3]; n not a multiple of any vector width or block.
Sample random_sample(std::size_t n, AngleUnit unit, unsigned seed) {
    std::mt19937_64 rng(seed);
    const double turn = unit == AngleUnit::Degrees ? 360.0 : 2.0 * kPi;
    const double quarter = unit == AngleUnit::Degrees ? 89.0 : deg_to_rad(89.0);
    std::uniform_real_distribution<double> polar(0.0, quarter), azim(-3.0 * turn, 3.0 * turn),
        slope(0.1, 3.0);
    Sample s;
    for (std::size_t k = 0; k < n; ++k) {
        s.ti.push_back(polar(rng));
        s.ts.push_back(polar(rng));
        // Far-out azimuths: 1000 turns in degrees (reduced exactly by both paths); 20 turns in
        // radians (the scalar path wraps with the double nearest 2π, off by 2.4e-16 per turn).
        const double far = unit == AngleUnit::Degrees ? 1000.0 : 20.0;
        s.ps.push_back(azim(rng) + (k % 97 == 0 ? far * turn : 0.0));
        s.m.push_back(slope(rng));
    }
    s.ti[0] = 0.0;  // normal incidence, normal view, specular and retro directions
    s.ts[0] = 0.0;
    s.ti[1] = s.ts[1] = quarter / 2;
    s.ps[1] = 0.0;
    s.ti[2] = s.ts[2] = quarter / 3;
    s.ps[2] = turn / 2;
    return s;
}

std::vector<VectorIsa> available_isas() {
    std::vector<VectorIsa> out;
    for (VectorIsa isa : {VectorIsa::Generic, VectorIsa::Avx2, VectorIsa::Avx512})
        if (set_vector_isa_cap(isa) == isa) out.push_back(isa);
    set_vector_isa_cap(VectorIsa::Avx512);
    return out;
}

}  // namespace

TEST(BrightnessBatch, MatchesTheScalarFunctionOnEveryIsaAndModel) {
    constexpr std::size_t n = 2053;
    double worst = 0.0;
    for (VectorIsa isa : available_isas()) {
        set_vector_isa_cap(isa);
        for (AngleUnit unit : {AngleUnit::Radians, AngleUnit::Degrees}) {
            const Sample s = random_sample(n, unit, 11);
            const double to_rad = unit == AngleUnit::Degrees ? kPi / 180.0 : 1.0;
            for (Correlation c : {Correlation::Gaussian, Correlation::Exponential})
                for (GeometricFactor f : {GeometricFactor::VernoldHarvey, GeometricFactor::Beckmann,
                                          GeometricFactor::Ogilvy, GeometricFactor::Kirchhoff})
                    for (Radiometry r : {Radiometry::Radiance, Radiometry::Intensity}) {
                        std::vector<double> out(n);
                        very_rough_brightness_batch({s.ti, s.ts, s.ps, s.m, unit}, out, {c, f, r});
                        for (std::size_t k = 0; k < n; ++k) {
                            // Degrees: reduced exactly (fmod by 360) before the conversion.
                            const double phi = unit == AngleUnit::Degrees
                                                   ? std::fmod(s.ps[k], 360.0) * to_rad
                                                   : s.ps[k];
                            const Geometry g =
                                make_geometry(s.ti[k] * to_rad, s.ts[k] * to_rad, phi);
                            const double ref = very_rough_brightness(g, s.m[k], c, f, r);
                            // As numpy's allclose: |out − ref| <= atol + rtol |ref|, with
                            // atol = 1e-300 for results that underflow (far outside the lobe).
                            const double diff = std::abs(out[k] - ref);
                            if (std::abs(ref) > 1e-280)
                                worst = std::max(worst, diff / std::abs(ref));
                            ASSERT_LE(diff, 1e-300 + kTolerance * std::abs(ref))
                                << to_string(isa) << " " << to_string(c) << " " << to_string(f)
                                << " " << to_string(r) << " element " << k << ": " << out[k]
                                << " vs " << ref;
                        }
                    }
        }
    }
    set_vector_isa_cap(VectorIsa::Avx512);
    RecordProperty("max_relative_difference", std::to_string(worst));
    std::printf("batch vs scalar: max relative difference %.3g over %zu ISAs\n", worst,
                available_isas().size());
}

TEST(BrightnessBatch, BroadcastsSingleValues) {
    const std::vector<double> ti = {0.1, 0.5, 0.9, 1.2, 0.0};
    const std::vector<double> ts = {0.3}, ps = {kPi}, m = {0.7};
    std::vector<double> out(ti.size());
    very_rough_brightness_batch({ti, ts, ps, m}, out, {Correlation::Exponential});
    for (std::size_t k = 0; k < ti.size(); ++k)
        EXPECT_NEAR(
            out[k],
            very_rough_brightness(make_geometry(ti[k], 0.3, kPi), 0.7, Correlation::Exponential),
            1e-12 * out[k]);
}

TEST(BrightnessBatch, ReportsTheFirstBadElement) {
    const Sample s = random_sample(5000, AngleUnit::Degrees, 5);
    for (VectorIsa isa : available_isas()) {
        set_vector_isa_cap(isa);
        Sample bad = s;
        bad.ts[3001] = std::nan("");
        bad.ti[4000] = 95.0;
        std::vector<double> out(bad.ti.size());
        try {
            very_rough_brightness_batch({bad.ti, bad.ts, bad.ps, bad.m, AngleUnit::Degrees}, out);
            FAIL() << "no exception";
        } catch (const InvalidArgument& e) {
            EXPECT_EQ(std::string(e.what()).rfind("element 3001: theta_s_deg = nan", 0), 0u)
                << e.what();
        }
        bad.ts[3001] = 10.0;
        bad.m[4999] = -1.0;
        std::size_t at = 0;
        EXPECT_THROW(
            very_rough_brightness_batch({bad.ti, bad.ts, bad.ps, bad.m, AngleUnit::Degrees}, out,
                                        {}, 4500, 5000, at),
            InvalidArgument);
        EXPECT_EQ(at, 4999u);
    }
    set_vector_isa_cap(VectorIsa::Avx512);
}

TEST(BrightnessBatch, RejectsMismatchedSizesAndRanges) {
    const std::vector<double> a(4, 0.2), b(3, 0.2), one(1, 0.5);
    std::vector<double> out(4);
    EXPECT_THROW(very_rough_brightness_batch({a, b, one, one}, out), InvalidArgument);
    std::size_t at = 0;
    EXPECT_THROW(very_rough_brightness_batch({a, a, one, one}, out, {}, 2, 5, at), InvalidArgument);
    std::vector<double> none;
    EXPECT_NO_THROW(very_rough_brightness_batch({none, none, none, none}, none));
}

TEST(BrightnessBatch, IsaNames) {
    EXPECT_EQ(parse_vector_isa("AVX2"), VectorIsa::Avx2);
    EXPECT_EQ(parse_vector_isa("best"), VectorIsa::Avx512);
    EXPECT_EQ(to_string(VectorIsa::Generic), "generic");
    EXPECT_THROW(parse_vector_isa("sse9"), InvalidArgument);
    EXPECT_LE(active_vector_isa(), cpu_vector_isa());
}
