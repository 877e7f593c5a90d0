// Steps 4 and 5 of the cylinder profile (cylinder_steps.hpp): the σ/T fits of the very-rough
// forms through the fit engine, the model curves (Lambert, Eq. 7, 9, 10) and the angle where each
// leaves the data, and the dark-limb check (docs/curved-objects.md, "Cylinder profile": models,
// fit, departure angle).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cylinder_steps.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image::detail {
namespace {

// The dark-limb warning's factor: a Lambert limb is cos 80° = 0.17 of its peak at 80°, some 25×
// a silhouette level at 1 % of the object's brightness.
constexpr double kDarkLimbFactor = 10.0;

}  // namespace

ProfileFit fit_profile(const std::vector<ProfileBin>& bins,
                       const std::vector<std::vector<ProfileNode>>& nodes, Correlation correlation,
                       GeometricFactor factor, Radiometry radiometry) {
    ProfileFit fit;
    fit.correlation = correlation;
    std::vector<std::size_t> used;
    LeastSquaresProblem problem;
    for (std::size_t b = 0; b < bins.size(); ++b) {
        if (!bins[b].in_fit) continue;
        used.push_back(b);
        problem.data.push_back(bins[b].brightness);
        problem.weights.push_back(1.0 / (bins[b].standard_error * bins[b].standard_error));
    }
    fit.bins = static_cast<int>(used.size());
    if (used.size() < 3) {
        fit.status = SolverStatus::NotIdentifiable;
        fit.message = concat(std::to_string(used.size()),
                             " bin(s) in the fit range; σ/T and the gain need at least 3");
        return fit;
    }
    ParameterSpec p;
    p.name = "sigma_over_T";
    p.lower = 1e-3;
    p.upper = 1e3;
    problem.parameters = {p};
    problem.residual = ResidualType::Absolute;
    problem.gain = GainMode::Profiled;
    // M_b(σ/T): the very-rough brightness (Eq. 4 or Eq. 5) averaged over the bin's nodes.
    problem.model = [&](std::span<const double> theta, std::span<double> out) {
        const double s = theta[0];
        for (std::size_t k = 0; k < used.size(); ++k) {
            double m = 0;
            for (const ProfileNode& n : nodes[used[k]])
                if (n.lit)
                    m += n.weight *
                         very_rough_brightness(n.geometry, s, correlation, factor, radiometry);
            if (!std::isfinite(m)) return false;
            out[k] = m;
        }
        return true;
    };
    const LeastSquaresResult r = solve_least_squares(problem);
    fit.status = r.status;
    fit.message = r.message;
    fit.aic = r.aic;
    fit.gain = r.gain;
    const FitParameter& sp = r.parameter("sigma_over_T");
    if (sp.identified && r.status != SolverStatus::Failed &&
        r.status != SolverStatus::NotIdentifiable) {
        fit.sigma_over_T = sp.value;
        if (r.covariance_available && !sp.at_bound) fit.sigma_over_T_stderr = sp.std_error;
    }
    return fit;
}

CylinderFits fit_cylinder_profile(const CylinderBins& bins, const CylinderOptions& options) {
    CylinderFits fits;
    // The two correlations side by side (independent problems; the same result whatever the
    // number of threads).
    run_bands(2, options.threads, [&](std::size_t k) {
        (k == 0 ? fits.gaussian : fits.exponential) = fit_profile(
            bins.bins, bins.nodes, k == 0 ? Correlation::Gaussian : Correlation::Exponential,
            options.factor, options.radiometry);
    });
    if (fits.gaussian.sigma_over_T && fits.exponential.sigma_over_T)
        fits.preferred = fits.exponential.aic < fits.gaussian.aic ? Correlation::Exponential
                                                                  : Correlation::Gaussian;
    else if (fits.exponential.sigma_over_T)
        fits.preferred = Correlation::Exponential;
    return fits;
}

std::optional<std::size_t> departure_bin(const std::vector<ProfileBin>& bins,
                                         const std::vector<double>& prediction, double k,
                                         std::size_t run) {
    const std::size_t n = bins.size();
    auto off = [&](std::size_t b) {
        return std::abs(prediction[b] - bins[b].brightness) > k * bins[b].standard_error;
    };
    for (std::size_t b = 0; b < n; ++b) {
        const std::size_t end = std::min(n, b + run);
        bool all = true;
        for (std::size_t j = b; j < end && all; ++j) all = off(j);
        if (all) return b;
    }
    return std::nullopt;
}

ProfileModelCurve profile_curve(ProfileModel model, std::optional<double> sigma_over_T,
                                const CylinderBins& bins, const CylinderOptions& options) {
    ProfileModelCurve curve;
    curve.model = model;
    curve.name = std::string(to_string(model));
    if (model != ProfileModel::Lambert) curve.sigma_over_T = sigma_over_T;
    const double s = curve.sigma_over_T.value_or(1.0);
    curve.prediction = bin_model_averages(bins.nodes, [&](const Geometry& g) {
        return profile_model_brightness(model, g, s, options.radiometry);
    });
    const double mx = *std::max_element(curve.prediction.begin(), curve.prediction.end());
    double ss = 0;
    for (std::size_t b = 0; b < bins.bins.size(); ++b) {
        curve.prediction[b] = mx > 0 ? curve.prediction[b] / mx : 0.0;
        const double e = curve.prediction[b] - bins.bins[b].brightness;
        ss += e * e;
    }
    curve.rms_difference = std::sqrt(ss / static_cast<double>(bins.bins.size()));
    curve.departure_bin =
        departure_bin(bins.bins, curve.prediction, options.departure_k, options.departure_bins);
    if (curve.departure_bin)
        curve.departure_theta_i_rad = bins.bins[*curve.departure_bin].theta_i_rad;
    return curve;
}

// A detected axis takes the silhouette's edge for the limb. On an object whose brightness fades
// smoothly to the silhouette's level (a narrow very-rough lobe lit from near the camera) the edge
// lies inside the true limb, and the radius, hence every angle, is off; a limb that stays bright
// to the edge (Lambert: cos 80° = 0.17) is found where it is. The sign: the profile 10° inside
// the detected limb is within a few times the silhouette's level.
std::optional<std::string> dark_limb_warning(const std::vector<ProfileBin>& bins, double maximum,
                                             double silhouette_level) {
    if (!(maximum > 0.0) || bins.empty()) return std::nullopt;
    // The bin nearest 80° (or the outermost one, when the profile stops short of 80°).
    const double level = silhouette_level / maximum;
    const double target = deg_to_rad(80.0);
    const auto distance = [&](const ProfileBin& b) {
        return std::abs(std::min(std::abs(b.alpha_rad), target) - target) -
               1e-3 * std::abs(b.alpha_rad);
    };
    const ProfileBin* near = &bins.front();
    for (const ProfileBin& b : bins)
        if (distance(b) < distance(*near)) near = &b;
    if (!(std::abs(near->alpha_rad) >= deg_to_rad(60.0) &&
          near->brightness < kDarkLimbFactor * level))
        return std::nullopt;
    return concat("the profile at ", check::format_number(rad_to_deg(std::abs(near->alpha_rad))),
                  "° from the axis (", check::format_number(near->brightness),
                  " of the maximum) is within ", check::format_number(kDarkLimbFactor),
                  "x the silhouette's level (", check::format_number(level),
                  "): the limb is dark, the detected edge is likely inside the true limb, so the "
                  "radius and the angles are biased; give the axis (or edges) of the cylinder");
}

}  // namespace roughscope::image::detail
