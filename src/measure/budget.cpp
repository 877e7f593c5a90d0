// The uncertainty budget of a flat sample's measurement (budget.hpp, docs/uncertainty.md): the
// measurement model from the inputs of the setup to E1/E2, σ/T, σ and T, and its propagation.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "finite_distance_detail.hpp"
#include "measure_inputs.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/validity.hpp"

namespace roughscope::image {
namespace {

constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The exponent of the sRGB curve's power segment (IEC 61966-2-1), the γ its uncertainty refers to.
constexpr double kSrgbExponent = 2.4;

// A region's mean on the linear scale of photo/image.hpp and what reading it did: enough to move
// it by an error of the black level or of the response's exponent.
struct RegionMean {
    double mean = 0.0;           // m: (s − b)/(W − b), s the linear code
    double white_dn = 1.0;       // W
    double black_dn = 0.0;       // b (the mean over the planes)
    double gamma = 0.0;          // the exponent the response was inverted with; 0: linear
    bool read_from_file = true;  // false: a merged bracket (its own response curve)
};

RegionMean region_mean(double mean, const ImageInfo& info, bool bracket) {
    RegionMean r;
    r.mean = mean;
    r.read_from_file = !bracket;
    r.white_dn = info.white_level_dn > 0.0 ? info.white_level_dn : 1.0;
    double b = 0.0;
    for (double level : info.black_level_dn) b += level;
    r.black_dn =
        info.black_level_dn.empty() ? 0.0 : b / static_cast<double>(info.black_level_dn.size());
    r.gamma = info.response == Response::Gamma  ? info.gamma
              : info.response == Response::Srgb ? kSrgbExponent
                                                : 0.0;
    return r;
}

// m after a black-level error δb (DN) and a response exponent γ + δγ, at the region's mean: the
// linear code s/W = (m (W − b) + b)/W is re-decoded as (s/W)^((γ + δγ)/γ), then
// m' = (s' − b − δb)/(W − b − δb) (photo/read.hpp's linear scale).
double perturbed_mean(const RegionMean& r, double d_black_dn, double d_gamma) {
    if (!r.read_from_file) return r.mean;
    const double span = r.white_dn - r.black_dn;
    double s = r.mean * span + r.black_dn;
    if (r.gamma > 0.0 && d_gamma != 0.0) {
        if (!(s > 0.0)) return kNaN;
        s = r.white_dn * std::pow(s / r.white_dn, (r.gamma + d_gamma) / r.gamma);
    }
    const double m = (s - r.black_dn - d_black_dn) / (span - d_black_dn);
    return m > 0.0 ? m : kNaN;
}

bool normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

// The model error of the very-rough Gaussian σ/T (Eq. 17, or Eq. 4 through the solver) where σ
// is unknown: the surface is assumed very rough (g ≥ kVeryRoughMinG at both captures), and over
// that range the exact series of Eq. 2 gives ratios that the very-rough inverse reads as
// s'(g) ≠ s. The largest |s'(g) − s| over g = g_min … 100 g_min (g_min = SetupTolerances::
// very_rough_min_g, default kVeryRoughMinG; σ/T = s held, σ from the smaller g of the two
// captures) is the half-width of a rectangular input (docs/uncertainty.md).
double very_rough_model_error(double s, const Geometry& g1, const Geometry& g2,
                              const MeasureRequest& request, bool closed) {
    ModelOptions o;
    o.regime = Regime::Series;
    o.factor = request.factor;
    o.radiometry = request.radiometry;
    o.wavelength_um = request.wavelength_um;
    TwoGeometryOptions t;
    t.factor = request.factor;
    t.radiometry = request.radiometry;
    const double vz = std::min(scattering_vector(g1, o.wavelength_um).vz,
                               scattering_vector(g2, o.wavelength_um).vz);
    double worst = 0.0;
    for (const double factor : {1.0, 1.4, 2.0, 3.0, 5.0, 10.0, 30.0, 100.0}) {
        const double g = factor * request.uncertainty.very_rough_min_g;
        const double sigma = std::sqrt(g) / std::abs(vz);
        const Surface surface{sigma, sigma / s, Correlation::Gaussian};
        const auto brightness = [&](const Geometry& geom) {
            return mean_scattered_power(geom, surface, o).diffuse *
                   radiometric_factor(o.radiometry, geom);
        };
        try {
            const double ratio = brightness(g1) / brightness(g2);
            const double read =
                closed ? sigma_over_T_from_ratio(Correlation::Gaussian, ratio, g1.theta_i_rad,
                                                 g2.theta_i_rad, request.factor)
                       : sigma_over_T_two_geometries(ratio, g1, g2, Correlation::Gaussian, t);
            worst = std::max(worst, std::abs(read - s));
        } catch (const Error&) {
            return kNaN;  // a ratio the very-rough inverse cannot read: no bound
        }
    }
    return worst;
}

// The tolerances in force: the declared ones, else the defaults (noted as assumed).
class Tolerances {
  public:
    Tolerances(const SetupTolerances& setup, std::vector<std::string>& assumed)
        : setup_(setup), assumed_(assumed) {}

    double get(const std::optional<double>& declared, std::string_view key, double fallback,
               std::string_view unit) {
        if (declared) return *declared;
        const std::string note = concat(key, " = ", format_significant(fallback, 3), unit);
        if (std::find(assumed_.begin(), assumed_.end(), note) == assumed_.end())
            assumed_.push_back(note);
        return fallback;
    }
    double angle_rad(const std::optional<double>& capture) {
        return deg_to_rad(
            capture ? *capture
                    : get(setup_.angle_deg, "angle_deg", kDefaultAngleUncertaintyDeg, "°"));
    }
    const SetupTolerances& setup() const { return setup_; }

  private:
    const SetupTolerances& setup_;
    std::vector<std::string>& assumed_;
};

// One diffuse capture of the pair: the indices of its inputs in x.
struct DiffuseInputs {
    std::size_t theta_i = kNone, theta_s = kNone, phi_s = kNone, exposure = kNone, noise = kNone;
    std::size_t black = kNone;  // the capture's black reference, linear units
    RegionMean region;
    double exposure_scale = 1.0;
    bool normal_view = false;
};

struct SpecularInputs {
    std::size_t theta = kNone, noise_tot = kNone, noise_dif = kNone, flat = kNone;
    std::size_t black = kNone;  // the capture's black reference, linear units
    RegionMean tot, dif;
};

// The measurement model: x (the inputs) → (E1/E2, σ/T Gaussian, σ/T exponential, σ, T, and the
// exact series' σ/T and T of both correlations).
class BudgetModel {
  public:
    BudgetModel(const MeasureRequest& request, const MeasureResult& result,
                std::vector<std::string>& assumed)
        : request_(request), result_(result), tol_(request.uncertainty, assumed) {
        build();
    }

    const std::vector<UncertainInput>& inputs() const { return inputs_; }
    const std::array<bool, kBudgetQuantityCount>& wanted() const { return wanted_; }

    // The outputs of one pass: the headline quantities (0–4), or the exact series' (5–8).
    void operator()(std::span<const double> x, std::span<std::optional<double>> y,
                    bool series_pass) const;

  private:
    std::size_t add(std::string source, double value, double u) {
        inputs_.push_back(UncertainInput{std::move(source), value, u});
        return inputs_.size() - 1;
    }
    void build();
    void build_diffuse(const std::vector<std::size_t>& pair);
    void build_specular(std::size_t k);
    std::optional<double> brightness(const DiffuseInputs& d, std::span<const double> x) const;
    std::optional<double> sigma(std::span<const double> x) const;
    static void series(double ratio, const Geometry& g1, const Geometry& g2, double s,
                       TwoGeometryOptions options, std::span<std::optional<double>> y);
    double lambda(std::span<const double> x) const {
        return lambda_ == kNone ? request_.wavelength_um : x[lambda_];
    }
    static std::optional<Geometry> geometry(const DiffuseInputs& d, std::span<const double> x) {
        return signed_geometry(x[d.theta_i], x[d.theta_s], x[d.phi_s]);
    }

    const MeasureRequest& request_;
    const MeasureResult& result_;
    Tolerances tol_;
    std::vector<UncertainInput> inputs_;
    std::array<bool, kBudgetQuantityCount> wanted_{};
    std::vector<DiffuseInputs> diffuse_;
    std::optional<SpecularInputs> specular_;
    std::size_t black_ = kNone, gamma_ = kNone, lambda_ = kNone, sigma_given_ = kNone;
    std::size_t model_gaussian_ = kNone;  // the very-rough model error of σ/T (Gaussian)
    // A lamp or camera at a finite distance: the multiplier of E1/E2 that brings it to the
    // nominal geometries (σ/T Gaussian, exponential, T given σ), held fixed at the measurement's.
    std::array<double, 3> ratio_correction_{1.0, 1.0, 1.0};
};

void BudgetModel::build() {
    std::vector<std::size_t> pair, specular;
    for (std::size_t k = 0; k < result_.captures.size(); ++k) {
        const CaptureMeasurement& c = result_.captures[k];
        if (c.spec.role == CaptureRole::Diffuse && c.brightness > 0.0) pair.push_back(k);
        if (c.spec.role == CaptureRole::Specular && c.highlight) specular.push_back(k);
    }
    bool raw = false, any_response = false, bracket_only = true;
    for (const CaptureMeasurement& c : result_.captures) {
        raw = raw || c.info.format == "raw";
        any_response = any_response || c.info.response != Response::Linear;
        bracket_only = bracket_only && !c.spec.bracket.empty();
    }
    const double white = result_.captures.empty() ? 1.0 : result_.captures[0].info.white_level_dn;
    // A black reference region measures each capture's black level (its standard error is that
    // capture's own input, below); else one black level error for every photograph.
    if (!bracket_only && !request_.black_reference) {
        black_ = add("black level (every photograph)", 0.0,
                     tol_.get(tol_.setup().black_level_dn, "black_level_dn",
                              (raw ? kDefaultRawBlackLevelFraction : kDefaultBlackLevelFraction) *
                                  (white > 0.0 ? white : 1.0),
                              " DN"));
    }
    if (!bracket_only) {
        if (any_response)
            gamma_ = add("response exponent", 0.0,
                         tol_.get(tol_.setup().response_gamma, "response_gamma",
                                  kDefaultResponseGammaUncertainty, ""));
    }
    // λ enters σ (Eq. 13) and T given σ (through g), not the very-rough σ/T.
    const bool specular_sigma =
        !request_.sigma_um && !specular.empty() && result_.sigma && result_.sigma->sigma_um;
    const bool sigma_known = request_.sigma_um || specular_sigma;
    if (specular_sigma || (pair.size() >= 2 && (result_.correlation_length || sigma_known)))
        lambda_ = add("wavelength", request_.wavelength_um,
                      tol_.get(tol_.setup().wavelength_um, "wavelength_um",
                               kDefaultWavelengthUncertaintyUm, " µm"));
    if (pair.size() >= 2) build_diffuse(pair);
    if (request_.sigma_um) {
        sigma_given_ = add("sigma_um (given)", *request_.sigma_um, request_.sigma_um_stderr);
        wanted_[3] = true;
    } else if (specular_sigma) {
        build_specular(specular.front());
        wanted_[3] = true;
    }
    if (pair.size() >= 2 && (sigma_given_ != kNone || specular_)) {
        const bool from_slope =
            result_.slope_gaussian && result_.slope_gaussian->T_um && !result_.fit;
        wanted_[4] = (result_.correlation_length && result_.correlation_length->T_um) || from_slope;
        // The exact series (σ known): T given σ in Regime::Series for each correlation.
        for (std::size_t o = 5; o < kBudgetQuantityCount; ++o) wanted_[o] = true;
    }
}

void BudgetModel::build_diffuse(const std::vector<std::size_t>& pair) {
    wanted_[0] = true;
    const CaptureMeasurement& c1 = result_.captures[pair[0]];
    const CaptureMeasurement& c2 = result_.captures[pair[1]];
    ratio_correction_ = {
        detail::ratio_correction(c1, c2, detail::CorrectedQuantity::SlopeGaussian),
        detail::ratio_correction(c1, c2, detail::CorrectedQuantity::SlopeExponential),
        detail::ratio_correction(c1, c2, detail::CorrectedQuantity::CorrelationLength)};
    wanted_[1] = result_.slope_gaussian && result_.slope_gaussian->sigma_over_T && !result_.fit;
    wanted_[2] =
        result_.slope_exponential && result_.slope_exponential->sigma_over_T && !result_.fit;
    for (std::size_t d = 0; d < 2; ++d) {
        const CaptureMeasurement& c = result_.captures[pair[d]];
        const std::string name = concat("capture ", std::to_string(pair[d] + 1));
        const Geometry& g = c.spec.geometry;
        const CaptureTolerances& t = c.spec.uncertainty;
        DiffuseInputs in;
        in.theta_i = add(concat("theta_i of ", name), g.theta_i_rad, tol_.angle_rad(t.theta_i_deg));
        // The camera not moved between the captures (the same view): one error for both.
        const Geometry* first = d == 1 ? &result_.captures[pair[0]].spec.geometry : nullptr;
        const bool same_view = first && g.theta_s_rad == first->theta_s_rad &&
                               g.phi_s_rad == first->phi_s_rad && !t.theta_s_deg && !t.phi_s_deg;
        if (same_view) {
            in.theta_s = diffuse_[0].theta_s;
            in.phi_s = diffuse_[0].phi_s;
            inputs_[in.theta_s].source = "theta_s of the camera (captures " +
                                         std::to_string(pair[0] + 1) + " and " +
                                         std::to_string(pair[1] + 1) + ")";
            inputs_[in.phi_s].source = "phi_s of the camera (captures " +
                                       std::to_string(pair[0] + 1) + " and " +
                                       std::to_string(pair[1] + 1) + ")";
        } else {
            in.theta_s =
                add(concat("theta_s of ", name), g.theta_s_rad, tol_.angle_rad(t.theta_s_deg));
            // At θs = 0 the azimuth names no direction: a tilt of the view is θs's (both signs).
            in.phi_s = add(concat("phi_s of ", name), g.phi_s_rad,
                           g.theta_s_rad == 0.0 ? 0.0 : tol_.angle_rad(t.phi_s_deg));
        }
        const bool needs_exposure = c.exposure_source.rfind("not needed", 0) != 0;
        in.exposure =
            add(concat("exposure of ", name), 0.0,
                needs_exposure && c.spec.bracket.empty()
                    ? (t.exposure_rel ? *t.exposure_rel
                                      : tol_.get(tol_.setup().exposure_rel, "exposure_rel",
                                                 kDefaultExposureUncertaintyRel, ""))
                    : 0.0);
        in.noise = add(concat("pixel noise of ", name), 0.0, c.brightness_relative_stderr);
        if (c.black_reference)
            in.black =
                add(concat("black reference of ", name), 0.0,
                    std::max(c.black_reference->stderr_pixel, c.black_reference->stderr_tiles));
        in.region = region_mean(c.region.average.mean, c.info, !c.spec.bracket.empty());
        in.exposure_scale = c.exposure_scale;
        in.normal_view = normal_view(g) && !(inputs_[in.theta_s].u > 0.0);
        diffuse_.push_back(in);
    }
    // σ unknown: the Gaussian σ/T rests on the very-rough limit; its model error is an input.
    if (wanted_[1] && !request_.sigma_um && !(result_.sigma && result_.sigma->sigma_um)) {
        const Geometry& g1 = result_.captures[pair[0]].spec.geometry;
        const Geometry& g2 = result_.captures[pair[1]].spec.geometry;
        const double b = very_rough_model_error(result_.slope_gaussian->sigma_over_T->value, g1, g2,
                                                request_, normal_view(g1) && normal_view(g2));
        if (std::isfinite(b)) {
            model_gaussian_ =
                add(concat("model: Eq. 17 (very rough) vs the exact series, g ≥ ",
                           format_significant(request_.uncertainty.very_rough_min_g, 3)),
                    0.0, b / std::sqrt(3.0));
            inputs_[model_gaussian_].distribution = InputDistribution::Rectangular;
        }
    }
}

void BudgetModel::build_specular(std::size_t k) {
    const CaptureMeasurement& c = result_.captures[k];
    const HighlightMeasurement& h = *c.highlight;
    const std::string name = concat("capture ", std::to_string(k + 1));
    SpecularInputs in;
    in.theta = add(concat("theta of ", name, " (specular)"), c.spec.geometry.theta_i_rad,
                   tol_.angle_rad(c.spec.uncertainty.theta_i_deg));
    in.noise_tot =
        add(concat("pixel noise of the highlight of ", name), 0.0, h.E_tot_relative_stderr);
    in.noise_dif =
        add(concat("pixel noise of the surround of ", name), 0.0, h.E_dif_relative_stderr);
    in.flat = add("flat field (highlight vs surround)", 0.0,
                  tol_.get(tol_.setup().flat_field_rel, "flat_field_rel",
                           request_.flat_field ? kDefaultFlatFieldGivenUncertaintyRel
                                               : kDefaultFlatFieldUncertaintyRel,
                           ""));
    if (c.black_reference)
        in.black = add(concat("black reference of ", name), 0.0,
                       std::max(c.black_reference->stderr_pixel, c.black_reference->stderr_tiles));
    in.tot = region_mean(h.core.average.mean, c.info, !c.spec.bracket.empty());
    in.dif = region_mean(h.annulus.average.mean, c.info, !c.spec.bracket.empty());
    specular_ = in;
}

std::optional<double> BudgetModel::brightness(const DiffuseInputs& d,
                                              std::span<const double> x) const {
    const double m = perturbed_mean(d.region, black_ == kNone ? 0.0 : x[black_],
                                    gamma_ == kNone ? 0.0 : x[gamma_]) -
                     (d.black == kNone ? 0.0 : x[d.black]);
    const double scale = d.exposure_scale * (1.0 + x[d.exposure]);
    if (!(m > 0.0) || !(scale > 0.0)) return std::nullopt;
    return m * (1.0 + x[d.noise]) / scale;
}

// σ: given, or Eq. 13 from the specular capture's highlight and surround.
std::optional<double> BudgetModel::sigma(std::span<const double> x) const {
    if (sigma_given_ != kNone)
        return x[sigma_given_] > 0.0 ? std::optional(x[sigma_given_]) : std::nullopt;
    if (!specular_) return std::nullopt;
    const SpecularInputs& s = *specular_;
    const double db = black_ == kNone ? 0.0 : x[black_];
    const double dg = gamma_ == kNone ? 0.0 : x[gamma_];
    const double ref = s.black == kNone ? 0.0 : x[s.black];
    const double tot =
        (perturbed_mean(s.tot, db, dg) - ref) * (1.0 + x[s.noise_tot]) * (1.0 + x[s.flat]);
    const double dif = (perturbed_mean(s.dif, db, dg) - ref) * (1.0 + x[s.noise_dif]);
    const double theta = std::abs(x[s.theta]);
    if (!(tot > dif) || !(dif > 0.0) || !(theta < kPi / 2) || !(lambda(x) > 0.0))
        return std::nullopt;
    return sigma_from_specular(specular_reflectance_from_brightness(tot, dif), theta, lambda(x),
                               request_.R0);
}

void BudgetModel::operator()(std::span<const double> x, std::span<std::optional<double>> y,
                             bool series_pass) const {
    std::optional<double> ratio;
    std::optional<Geometry> g1, g2;
    if (diffuse_.size() == 2) {
        const auto e1 = brightness(diffuse_[0], x);
        const auto e2 = brightness(diffuse_[1], x);
        g1 = geometry(diffuse_[0], x);
        g2 = geometry(diffuse_[1], x);
        if (e1 && e2 && g1 && g2) ratio = *e1 / *e2;
    }
    if (wanted_[0] && !series_pass) y[0] = ratio;
    TwoGeometryOptions options;
    options.factor = request_.factor;
    options.radiometry = request_.radiometry;
    options.wavelength_um = lambda(x);
    if (series_pass) {
        std::optional<double> s;
        try {
            s = sigma(x);
        } catch (const Error&) {
        }
        if (wanted_[5] && s && ratio && lambda(x) > 0.0) series(*ratio, *g1, *g2, *s, options, y);
        return;
    }
    const bool closed = diffuse_.size() == 2 && diffuse_[0].normal_view && diffuse_[1].normal_view;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const std::size_t o = c == Correlation::Gaussian ? 1 : 2;
        if (!wanted_[o] || !ratio) continue;
        const double r = *ratio * ratio_correction_[o - 1];
        try {
            y[o] = closed ? sigma_over_T_from_ratio(c, r, g1->theta_i_rad, g2->theta_i_rad,
                                                    request_.factor)
                          : sigma_over_T_two_geometries(r, *g1, *g2, c, options);
        } catch (const Error&) {
        }
        if (o == 1 && y[1] && model_gaussian_ != kNone) *y[1] += x[model_gaussian_];
    }
    std::optional<double> s;
    try {
        s = sigma(x);
    } catch (const Error&) {
    }
    if (wanted_[3]) y[3] = s;
    if (!wanted_[4] || !s || !ratio || !(lambda(x) > 0.0)) return;
    const double r = *ratio * ratio_correction_[2];
    try {
        if (result_.correlation_length && result_.correlation_length->T_um) {
            options.regime = result_.correlation_length_regime.value_or(Regime::SlightlyRough);
            const Correlation c = request_.correlation;
            y[4] =
                closed && info(c).slightly_rough_inverse && options.regime == Regime::SlightlyRough
                    ? correlation_length_from_ratio(r, *s, g1->theta_i_rad, g2->theta_i_rad,
                                                    lambda(x), request_.factor)
                    : correlation_length_two_geometries(r, *g1, *g2, *s, c, options);
        } else if (y[1]) {
            y[4] = *s / *y[1];
        }
    } catch (const Error&) {
    }
}

// The exact series with σ known (Eq. 2 summed, scattering/beckmann.hpp): T given σ from E1/E2 in
// Regime::Series for each correlation, and σ/T = σ/T_series (outputs 5–8).
void BudgetModel::series(double ratio, const Geometry& g1, const Geometry& g2, double s,
                         TwoGeometryOptions options, std::span<std::optional<double>> y) {
    options.regime = Regime::Series;
    for (const Correlation c : {Correlation::Gaussian, Correlation::Exponential}) {
        const std::size_t o = c == Correlation::Gaussian ? 0 : 1;
        try {
            const double T = correlation_length_two_geometries(ratio, g1, g2, s, c, options);
            y[5 + o] = s / T;
            y[7 + o] = T;
        } catch (const Error&) {
        }
    }
}

void check_tolerance(const std::string& where, std::string_view key,
                     const std::optional<double>& v) {
    if (v) check::non_negative(concat(where, ": uncertainty.", key), *v);
}

}  // namespace

std::optional<Geometry> signed_geometry(double theta_i, double theta_s, double phi_s) {
    if (theta_i < 0.0) {
        theta_i = -theta_i;
        phi_s += kPi;
    }
    if (theta_s < 0.0) {
        theta_s = -theta_s;
        phi_s += kPi;
    }
    if (!(theta_i < kPi / 2) || !(theta_s < kPi / 2)) return std::nullopt;
    return Geometry{theta_i, theta_s, phi_s};
}

void detail::check_tolerances(const MeasureRequest& request) {
    const std::string src = request.source.empty() ? std::string("measure") : request.source;
    const SetupTolerances& t = request.uncertainty;
    check_tolerance(src, "angle_deg", t.angle_deg);
    check_tolerance(src, "exposure_rel", t.exposure_rel);
    check_tolerance(src, "black_level_dn", t.black_level_dn);
    check_tolerance(src, "response_gamma", t.response_gamma);
    check_tolerance(src, "wavelength_um", t.wavelength_um);
    check_tolerance(src, "flat_field_rel", t.flat_field_rel);
    if (!(t.very_rough_min_g >= 1.0 && t.very_rough_min_g <= 1e6))
        throw InvalidArgument(concat(
            src, ": uncertainty.very_rough_min_g = ", check::format_number(t.very_rough_min_g),
            " must be in [1, 1e6]"));
    for (std::size_t k = 0; k < request.captures.size(); ++k) {
        const CaptureTolerances& c = request.captures[k].uncertainty;
        const std::string name = concat(src, ": captures[", std::to_string(k), "]");
        check_tolerance(name, "theta_i_deg", c.theta_i_deg);
        check_tolerance(name, "theta_s_deg", c.theta_s_deg);
        check_tolerance(name, "phi_s_deg", c.phi_s_deg);
        check_tolerance(name, "exposure_rel", c.exposure_rel);
    }
}

std::optional<UncertaintyBudget> uncertainty_budget(const MeasureRequest& request,
                                                    const MeasureResult& result) {
    if (request.object.shape != ObjectShape::Plane) return std::nullopt;
    UncertaintyBudget budget;
    const BudgetModel model(request, result, budget.assumed);
    const auto& wanted = model.wanted();
    if (std::none_of(wanted.begin(), wanted.end(), [](bool w) { return w; })) return std::nullopt;
    const std::vector<std::string> names(std::begin(kBudgetQuantities),
                                         std::end(kBudgetQuantities));
    const Propagation p = propagate_uncertainty(
        model.inputs(), names,
        [&model](std::span<const double> x, std::span<std::optional<double>> y) {
            model(x, y, false);
        },
        request.propagation);
    budget.method = p.method;
    budget.method_reason = p.reason;
    budget.warnings = p.warnings;
    // The exact series (outputs 5–8): first order, in a pass of its own — each evaluation solves
    // the series for T, too slow for the Monte Carlo's 10⁴–10⁵ trials; the series is smooth in
    // its inputs (docs/uncertainty.md).
    std::optional<Propagation> series;
    if (wanted[5]) {
        PropagationOptions first_order = request.propagation;
        first_order.method = PropagationMethod::FirstOrder;
        series = propagate_uncertainty(
            model.inputs(), names,
            [&model](std::span<const double> x, std::span<std::optional<double>> y) {
                model(x, y, true);
            },
            first_order);
    }
    for (std::size_t o = 0; o < names.size(); ++o) {
        const Propagation& from = o >= 5 ? *series : p;
        if (wanted[o] && from.outputs[o]) budget.quantities.push_back({names[o], *from.outputs[o]});
    }
    if (!budget.assumed.empty()) {
        std::string list;
        for (const auto& a : budget.assumed) list += (list.empty() ? "" : ", ") + a;
        budget.warnings.insert(budget.warnings.begin(),
                               concat("uncertainty: the budget rests on assumed tolerances (", list,
                                      "): declare the setup's in the capture file's "
                                      "\"uncertainty\" (docs/uncertainty.md)"));
    }
    return budget;
}

}  // namespace roughscope::image
