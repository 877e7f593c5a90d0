// The light's direction from a mirror sphere (objects/mirror_sphere.hpp) against spheres rendered
// here with a known light: for every pixel (3 × 3 samples) the normal of the orthographic sphere,
// the mirror direction of the view (written out below, not the library's), a narrow lobe
// exp(−angle²/2w²) around the light plus a dim Lambertian term, a dark background, Gaussian
// noise, quantised to 8 or 16 bits (pixels at full scale flagged saturated).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;

struct Render {
    std::size_t size = 320;
    double cx = 161.3, cy = 158.6, r = 140.0;
    Eigen::Vector3d light = Eigen::Vector3d(0, 0, 1);
    double lobe_deg = 1.5;  // w
    double peak = 0.9;      // lobe brightness at its centre (> 1: saturated core)
    double diffuse = 0.08;  // ρ of the Lambertian term
    double background = 0.01;
    double noise = 0.003;
    int bits = 16;
    std::uint64_t seed = 1;
};

Eigen::Vector3d light_from(double theta_deg, double phi_deg) {
    const double t = deg_to_rad(theta_deg), p = deg_to_rad(phi_deg);
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return rad_to_deg(std::atan2(a.cross(b).norm(), a.dot(b)));
}

// Brightness of the sphere's point with image offset (dx, dy) from the centre (image y down).
double sphere_radiance(double dx, double dy, const Render& s) {
    const double nx = dx / s.r, ny = -dy / s.r, rho2 = nx * nx + ny * ny;
    if (rho2 >= 1.0) return s.background;
    const double nz = std::sqrt(1.0 - rho2);
    // Mirror direction of V = (0, 0, 1): 2 n_z n − V.
    const Eigen::Vector3d mirror(2 * nz * nx, 2 * nz * ny, 2 * nz * nz - 1);
    const double a = angle_deg(mirror, s.light);
    const double lambert = std::max(0.0, nx * s.light.x() + ny * s.light.y() + nz * s.light.z());
    return s.peak * std::exp(-a * a / (2 * s.lobe_deg * s.lobe_deg)) + s.diffuse * lambert;
}

LinearImage render(const Render& s) {
    LinearImage img;
    img.width = img.height = s.size;
    img.channels = 1;
    img.values.resize(s.size * s.size);
    img.flags.assign(s.size * s.size, 0);
    img.info.source = "rendered";
    std::mt19937_64 rng(s.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    const double full = std::ldexp(1.0, s.bits) - 1.0;
    for (std::size_t row = 0; row < s.size; ++row)
        for (std::size_t col = 0; col < s.size; ++col) {
            double e = 0;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    e += sphere_radiance(static_cast<double>(col) + (2 * j + 1) / 6.0 - s.cx,
                                         static_cast<double>(row) + (2 * i + 1) / 6.0 - s.cy, s) /
                         9.0;
            e += s.noise * gauss(rng);
            const double code = std::round(std::clamp(e, 0.0, 1.0) * full);
            img.values[row * s.size + col] = static_cast<float>(code / full);
            if (code >= full) img.flags[row * s.size + col] = kPixelSaturated;
        }
    return img;
}

CircleFit circle_of(const Render& s) {
    CircleFit c;
    c.centre_x_px = s.cx;
    c.centre_y_px = s.cy;
    c.radius_px = s.r;
    return c;
}

TEST(MirrorSphere, GeometryOfTheFrame) {
    CircleFit c;
    c.centre_x_px = 50;
    c.centre_y_px = 40;
    c.radius_px = 20;
    const Eigen::Vector3d v(0, 0, 1);
    // The centre reflects V into itself.
    EXPECT_NEAR(angle_deg(reflect_view(mirror_sphere_normal(50, 40, c), v), v), 0.0, 1e-12);
    // A normal tilted by θ/2 reflects V into a light θ away, on the same side: right of the
    // centre → +x (φ = 0), above it (image y smaller) → +y (φ = 90°).
    const double t = 50.0, rho = std::sin(deg_to_rad(t / 2));
    const Eigen::Vector3d right = reflect_view(mirror_sphere_normal(50 + 20 * rho, 40, c), v);
    EXPECT_NEAR(polar_angle_deg(right), t, 1e-9);
    EXPECT_NEAR(azimuth_deg(right), 0.0, 1e-9);
    const Eigen::Vector3d up = reflect_view(mirror_sphere_normal(50, 40 - 20 * rho, c), v);
    EXPECT_NEAR(polar_angle_deg(up), t, 1e-9);
    EXPECT_NEAR(azimuth_deg(up), 90.0, 1e-9);
    // The law of reflection: equal angles with n, coplanar.
    const Eigen::Vector3d n = mirror_sphere_normal(43, 47, c);
    const Eigen::Vector3d l = reflect_view(n, v);
    EXPECT_NEAR(l.norm(), 1.0, 1e-12);
    EXPECT_NEAR(angle_deg(l, n), angle_deg(v, n), 1e-9);
    EXPECT_NEAR(l.dot(n.cross(v)), 0.0, 1e-12);
}

TEST(MirrorSphere, LightAtTheCameraHasItsHighlightAtTheCentre) {
    Render s;
    s.noise = 0.0;
    // Centred on a pixel centre, the sampled lobe is symmetric: exactly at the centre.
    s.cx = s.cy = 160.5;
    const MirrorSphereLight centred = mirror_sphere_light(render(s), circle_of(s));
    EXPECT_NEAR(centred.highlight_x_px, s.cx, 1e-6);
    EXPECT_NEAR(centred.highlight_y_px, s.cy, 1e-6);
    EXPECT_LT(centred.theta_deg, 1e-6);
    // Off the grid, to a few hundredths of a pixel (the lobe sampled by pixels of 2 px σ).
    s.cx = 161.3;
    s.cy = 158.6;
    const MirrorSphereLight m = mirror_sphere_light(render(s), circle_of(s));
    EXPECT_NEAR(m.highlight_x_px, s.cx, 0.05);
    EXPECT_NEAR(m.highlight_y_px, s.cy, 0.05);
    EXPECT_LT(m.theta_deg, 0.05);
    EXPECT_NEAR(m.light.norm(), 1.0, 1e-12);
    EXPECT_EQ(m.blobs, 1U);
    EXPECT_GT(m.highlight_pixels, 3U);
    EXPECT_LT(m.highlight_pixels, 60U);
    EXPECT_TRUE(m.warnings.empty());
}

// Over a grid of lights (θ up to 60°, several φ), 8 and 16 bits, unsaturated and saturated
// cores: within 0.3°.
TEST(MirrorSphere, RecoversTheLightOverAGrid) {
    double worst = 0;
    int cases = 0;
    std::uint64_t seed = 10;
    for (const double theta : {0.0, 15.0, 30.0, 45.0, 60.0})
        for (const double phi : {0.0, 50.0, 130.0, 220.0, 310.0}) {
            if (theta == 0.0 && phi > 0.0) continue;
            for (const int bits : {8, 16})
                for (const double peak : {0.9, 2.5}) {
                    Render s;
                    s.light = light_from(theta, phi);
                    s.bits = bits;
                    s.peak = peak;
                    s.seed = seed++;
                    const MirrorSphereLight m = mirror_sphere_light(render(s), circle_of(s));
                    const double err = angle_deg(m.light, s.light);
                    worst = std::max(worst, err);
                    ++cases;
                    EXPECT_LT(err, 0.3) << "theta " << theta << " phi " << phi << " bits " << bits
                                        << " peak " << peak;
                    EXPECT_NEAR(m.theta_deg, theta, 0.3);
                    if (peak > 1.0) {
                        EXPECT_GT(m.saturated_pixels, 0U);
                    }
                    EXPECT_EQ(m.blobs, 1U);
                    EXPECT_GT(m.angle_uncertainty_deg, 0.0);
                }
        }
    std::printf("mirror sphere grid: %d cases, worst error %.4f deg\n", cases, worst);
}

// With the circle known exactly (circle_uncertainty_px = 0), the stated uncertainty covers the
// error of noisy spheres: error < 3u in at least 95 % of the trials.
TEST(MirrorSphere, UncertaintyCoversTheErrorOfNoisySpheres) {
    int covered = 0, trials = 0;
    double sum_ratio2 = 0, worst = 0;
    std::uint64_t seed = 1000;
    for (const double theta : {10.0, 35.0, 60.0})
        for (const double noise : {0.01, 0.03})
            for (int rep = 0; rep < 6; ++rep) {
                Render s;
                s.light = light_from(theta, 40.0 + 70.0 * rep);
                s.noise = noise;
                s.bits = rep % 2 ? 8 : 16;
                s.seed = seed++;
                MirrorSphereOptions o;
                o.circle_uncertainty_px = 0.0;
                const MirrorSphereLight m =
                    mirror_sphere_light(render(s), circle_of(s), nullptr, o);
                const double err = angle_deg(m.light, s.light);
                worst = std::max(worst, err);
                sum_ratio2 += (err / m.angle_uncertainty_deg) * (err / m.angle_uncertainty_deg);
                covered += err < 3.0 * m.angle_uncertainty_deg;
                ++trials;
            }
    std::printf("mirror sphere coverage: %d of %d within 3u, RMS error/u %.3f, worst %.4f deg\n",
                covered, trials, std::sqrt(sum_ratio2 / trials), worst);
    EXPECT_GE(covered, static_cast<int>(std::ceil(0.95 * trials)));
    EXPECT_LT(worst, 0.3);
}

TEST(MirrorSphere, CircleUncertaintyIsPropagated) {
    Render s;
    s.light = light_from(30, 0);
    const LinearImage img = render(s);
    MirrorSphereOptions exact;
    exact.circle_uncertainty_px = 0;
    exact.centroid_floor_px = 0;
    const double u0 = mirror_sphere_light(img, circle_of(s), nullptr, exact).angle_uncertainty_deg;
    const double u1 = mirror_sphere_light(img, circle_of(s)).angle_uncertainty_deg;
    // A 0.5 px error of cx alone moves the normal by 0.5/r rad and L by about twice that.
    EXPECT_GT(u1, rad_to_deg(2 * 0.5 / s.r));
    EXPECT_GT(u1, 3 * u0);
    // A shifted circle moves the light by about what the uncertainty says per px.
    CircleFit shifted = circle_of(s);
    shifted.centre_x_px += 0.5;
    const double moved = angle_deg(mirror_sphere_light(img, shifted).light,
                                   mirror_sphere_light(img, circle_of(s)).light);
    EXPECT_NEAR(moved, rad_to_deg(2 * 0.5 / (s.r * std::cos(deg_to_rad(15)))), 0.05);
}

TEST(MirrorSphere, CircleFromAMask) {
    Render s;
    std::vector<std::uint8_t> mask(s.size * s.size, 0);
    for (std::size_t row = 0; row < s.size; ++row)
        for (std::size_t col = 0; col < s.size; ++col) {
            const double dx = col + 0.5 - s.cx, dy = row + 0.5 - s.cy;
            mask[row * s.size + col] = dx * dx + dy * dy < s.r * s.r;
        }
    const CircleFit c = circle_from_mask(mask, s.size, s.size);
    EXPECT_NEAR(c.centre_x_px, s.cx, 0.05);
    EXPECT_NEAR(c.centre_y_px, s.cy, 0.05);
    EXPECT_NEAR(c.radius_px, s.r, 0.05);
    s.light = light_from(40, 200);
    const MirrorSphereLight m = mirror_sphere_light(render(s), c, &mask);
    EXPECT_LT(angle_deg(m.light, s.light), 0.3);
    EXPECT_THROW(circle_from_mask(mask, s.size, s.size - 1), InvalidArgument);
    EXPECT_THROW(circle_from_mask(std::vector<std::uint8_t>(64, 1), 8, 8), InvalidArgument);
}

TEST(MirrorSphere, WarnsNearTheLimbAndForSeveralBlobs) {
    Render s;
    s.light = light_from(150, 30);  // n at 75°, ρ ≈ 0.97
    s.noise = 0;
    MirrorSphereLight m = mirror_sphere_light(render(s), circle_of(s));
    EXPECT_GT(m.highlight_rho, 0.9);
    ASSERT_FALSE(m.warnings.empty());
    EXPECT_NE(m.warnings[0].find("near the limb"), std::string::npos);
    EXPECT_LT(angle_deg(m.light, s.light), 1.0);

    // A second, dimmer highlight: the brightest is used, and a mask removes the other.
    Render a;
    a.light = light_from(30, 0);
    Render b = a;
    b.light = light_from(30, 180);
    b.peak = 0.6;
    LinearImage img = render(a);
    const LinearImage second = render(b);
    for (std::size_t k = 0; k < img.values.size(); ++k)
        img.values[k] = std::max(img.values[k], second.values[k]);
    m = mirror_sphere_light(img, circle_of(a));
    EXPECT_EQ(m.blobs, 2U);
    EXPECT_LT(angle_deg(m.light, a.light), 0.3);
    ASSERT_EQ(m.warnings.size(), 1U);
    EXPECT_NE(m.warnings[0].find("2 separate bright blobs"), std::string::npos);
    std::vector<std::uint8_t> left(img.pixel_count(), 0);
    for (std::size_t row = 0; row < a.size; ++row)
        for (std::size_t col = 0; col < a.size / 2; ++col) left[row * a.size + col] = 1;
    m = mirror_sphere_light(img, circle_of(a), &left);
    EXPECT_EQ(m.blobs, 1U);
    EXPECT_LT(angle_deg(m.light, b.light), 0.3);
}

TEST(MirrorSphere, RefusesBadInput) {
    Render s;
    const LinearImage img = render(s);
    CircleFit c = circle_of(s);
    c.centre_x_px = 100;  // r = 140: the disc leaves the image
    try {
        mirror_sphere_light(img, c);
        FAIL() << "no exception";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("centre x = 100 px"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("valid range [140, 180]"), std::string::npos)
            << e.what();
    }
    c = circle_of(s);
    c.radius_px = 4;
    EXPECT_THROW(mirror_sphere_light(img, c), InvalidArgument);
    c.radius_px = std::nan("");
    EXPECT_THROW(mirror_sphere_light(img, c), InvalidArgument);
    MirrorSphereOptions o;
    o.view = Eigen::Vector3d(0, 0, 2);
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), nullptr, o), InvalidArgument);
    o = {};
    o.threshold_fraction = 1.0;
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), nullptr, o), InvalidArgument);
    o = {};
    o.circle_uncertainty_px = -1;
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), nullptr, o), InvalidArgument);
    o.circle_uncertainty_px = 1e300;  // above r: refused, not an overflowing angle
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), nullptr, o), InvalidArgument);
    const std::vector<std::uint8_t> short_mask(10, 1);
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), &short_mask), InvalidArgument);
    // A sphere without a highlight: matte (the light's lobe off), noisy.
    Render matte = s;
    matte.peak = 0;
    matte.diffuse = 0.5;
    matte.noise = 0.01;
    try {
        mirror_sphere_light(render(matte), circle_of(matte));
        FAIL() << "no exception";
    } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find("no highlight"), std::string::npos) << e.what();
    }
    const std::vector<std::uint8_t> empty_mask(img.pixel_count(), 0);
    EXPECT_THROW(mirror_sphere_light(img, circle_of(s), &empty_mask), DataError);
}

}  // namespace
