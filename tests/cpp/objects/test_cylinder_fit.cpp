// Steps 4 and 5 of the cylinder profile (objects/cylinder_steps.hpp): the σ/T fits of Eq. 9 and
// Eq. 10 (paper §3.4, §5.2) recover the σ/T of brightness rendered by the model, and the
// departure angle of a model equal to the data is "never".
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "objects/cylinder_steps.hpp"
#include "roughscope/scattering/beckmann.hpp"

namespace {

using namespace roughscope;
using namespace roughscope::image;
using namespace roughscope::image::detail;

// Bins of 2° from 1° to 79° lit from the camera, each with 5 nodes across it; brightness
// gain · the bin average of `model` at σ/T, standard error `se`.
CylinderBins rendered_bins(ProfileModel model, double sigma_over_T, double gain, double se) {
    const Eigen::Vector3d z(0.0, 0.0, 1.0);
    CylinderBins bins;
    for (double lo_deg = 0.0; lo_deg < 80.0; lo_deg += 2.0) {
        std::vector<ProfileNode> nodes;
        for (int k = 0; k < 5; ++k) {
            const double alpha = deg_to_rad(lo_deg + 0.2 + 0.4 * k);
            nodes.push_back(cylinder_node(std::sin(alpha), 0.2, 1.0, 0.0, z, z));
        }
        ProfileBin b;
        b.alpha_rad = deg_to_rad(lo_deg + 1.0);
        b.theta_i_rad = b.alpha_rad;
        b.geometry = cylinder_node(std::sin(b.alpha_rad), 1.0, 1.0, 0.0, z, z).geometry;
        double m = 0;
        for (const ProfileNode& n : nodes)
            m += n.weight * profile_model_brightness(model, n.geometry, sigma_over_T);
        b.brightness = gain * m;
        b.standard_error = se;
        b.in_fit = b.theta_i_rad <= deg_to_rad(60.0);
        bins.bins.push_back(b);
        bins.nodes.push_back(std::move(nodes));
    }
    return bins;
}

TEST(CylinderFit, RecoversTheSigmaOverTOfBrightnessRenderedByTheModel) {
    for (const double s : {0.2, 0.5, 1.5}) {
        SCOPED_TRACE(::testing::Message() << "sigma/T " << s);
        CylinderOptions o;
        const CylinderFits g =
            fit_cylinder_profile(rendered_bins(ProfileModel::VhGaussian, s, 0.7, 1e-3), o);
        ASSERT_TRUE(g.gaussian.sigma_over_T.has_value()) << g.gaussian.message;
        EXPECT_NEAR(*g.gaussian.sigma_over_T / s, 1.0, 1e-6);
        EXPECT_NEAR(g.gaussian.gain, 0.7, 1e-6);
        EXPECT_EQ(g.gaussian.bins, 30);  // 1°, 3°, ..., 59°
        EXPECT_EQ(g.preferred, Correlation::Gaussian);
        const CylinderFits e =
            fit_cylinder_profile(rendered_bins(ProfileModel::VhExponential, s, 0.7, 1e-3), o);
        ASSERT_TRUE(e.exponential.sigma_over_T.has_value()) << e.exponential.message;
        EXPECT_NEAR(*e.exponential.sigma_over_T / s, 1.0, 1e-6);
        EXPECT_EQ(e.preferred, Correlation::Exponential);
    }
}

TEST(CylinderFit, FewerThanThreeBinsInTheFitRangeAreNotIdentifiable) {
    CylinderBins bins = rendered_bins(ProfileModel::VhGaussian, 0.5, 1.0, 1e-3);
    for (std::size_t b = 2; b < bins.bins.size(); ++b) bins.bins[b].in_fit = false;
    const CylinderFits f = fit_cylinder_profile(bins, CylinderOptions{});
    EXPECT_EQ(f.gaussian.status, SolverStatus::NotIdentifiable);
    EXPECT_FALSE(f.gaussian.sigma_over_T.has_value());
    EXPECT_FALSE(f.exponential.sigma_over_T.has_value());
    EXPECT_EQ(f.gaussian.bins, 2);
    EXPECT_NE(f.gaussian.message.find("at least 3"), std::string::npos);
}

TEST(CylinderDeparture, DataEqualToAModelNeverLeaveIt) {
    CylinderOptions o;
    for (const ProfileModel m : kProfileModels) {
        // Normalised as the profile is: the brightest bin is 1.
        CylinderBins bins = rendered_bins(m, 0.4, 1.0, 1e-3);
        double mx = 0;
        for (const ProfileBin& b : bins.bins) mx = std::max(mx, b.brightness);
        for (ProfileBin& b : bins.bins) b.brightness /= mx;
        const ProfileModelCurve c = profile_curve(m, 0.4, bins, o);
        EXPECT_EQ(c.name, std::string(to_string(m)));
        EXPECT_LT(c.rms_difference, 1e-12);
        EXPECT_FALSE(c.departure_bin.has_value());
        EXPECT_FALSE(c.departure_theta_i_rad.has_value());
        EXPECT_EQ(c.sigma_over_T.has_value(), m != ProfileModel::Lambert);
    }
    // Lambert's curve is cos θi whatever σ/T.
    const CylinderBins lambert = rendered_bins(ProfileModel::Lambert, 1.0, 1.0, 1e-3);
    EXPECT_EQ(profile_curve(ProfileModel::Lambert, 0.1, lambert, o).prediction,
              profile_curve(ProfileModel::Lambert, 5.0, lambert, o).prediction);
}

TEST(CylinderDeparture, TheFirstOfConsecutiveBinsBeyondKStandardErrors) {
    std::vector<ProfileBin> bins(10);
    for (ProfileBin& b : bins) {
        b.brightness = 0.5;
        b.standard_error = 0.01;
    }
    std::vector<double> prediction(10, 0.5);
    EXPECT_FALSE(departure_bin(bins, prediction, 3.0, 2).has_value());
    prediction[3] = 0.55;  // one bin off by 5 SE: noise, not a departure
    EXPECT_FALSE(departure_bin(bins, prediction, 3.0, 2).has_value());
    EXPECT_EQ(departure_bin(bins, prediction, 3.0, 1), 3U);
    prediction[6] = prediction[7] = prediction[8] = prediction[9] = 0.46;  // 4 SE below
    EXPECT_EQ(departure_bin(bins, prediction, 3.0, 2), 6U);
    EXPECT_FALSE(departure_bin(bins, prediction, 5.0, 2).has_value());
    // Fewer than `run` bins left: all of them.
    prediction.assign(10, 0.5);
    prediction[9] = 0.6;
    EXPECT_EQ(departure_bin(bins, prediction, 3.0, 3), 9U);
}

}  // namespace
