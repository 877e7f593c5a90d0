// Roughness from photographs: captures → region brightness → the §4 estimators (measure.hpp).
#include "roughscope/measure/measure.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <future>
#include <limits>
#include <thread>
#include <utility>

#include "finite_distance_detail.hpp"
#include "measure_inputs.hpp"
#include "measure_notes.hpp"
#include "measure_photometric.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/photo/radiometry.hpp"

namespace roughscope::image {
namespace {

constexpr std::array<NameEntry<CaptureRole>, 2> kRoleNames{{
    {"diffuse", CaptureRole::Diffuse},
    {"specular", CaptureRole::Specular},
}};

constexpr std::array<NameEntry<ObjectShape>, 5> kShapeNames{{
    {"plane", ObjectShape::Plane},
    {"cylinder", ObjectShape::Cylinder},
    {"sphere", ObjectShape::Sphere},
    {"normal_map", ObjectShape::NormalMap},
    {"photometric_stereo", ObjectShape::PhotometricStereo},
}};

bool is_profile(ObjectShape shape) {
    return shape == ObjectShape::Cylinder || shape == ObjectShape::Sphere;
}

std::string where(const MeasureRequest& request) {
    return request.source.empty() ? std::string("measure") : request.source;
}

// Relative standard error of a region mean: pixel noise or, when larger, the spread between
// tiles (texture).
double relative_stderr(const ChannelStatistics& s) {
    if (!(s.mean > 0.0)) return 0.0;
    return std::max(s.stderr_pixel, s.stderr_tiles) / s.mean;
}

void check_combination(const MeasureRequest& request);

void check_request(const MeasureRequest& request) {
    const std::string src = where(request);
    if (request.captures.empty())
        throw InvalidArgument(concat(src,
                                     ": no captures; give at least one specular capture or "
                                     "two diffuse captures"));
    check::positive(concat(src, ": wavelength_um"), request.wavelength_um, " µm");
    for (std::size_t c = 0; c < 3; ++c)
        check::positive(concat(src, ": channel_wavelengths_um[", std::to_string(c), "]"),
                        request.channel_wavelengths_um[c], " µm");
    check::positive(concat(src, ": R0"), request.R0);
    if (request.response_bracket.size() == 1)
        throw InvalidArgument(concat(src, ": response.bracket needs at least 2 photographs"));
    for (const BracketShot& shot : request.response_bracket)
        check::positive(concat(src, ": response.bracket: ", shot.image, ": exposure_s"),
                        shot.exposure_s, " s");
    if (request.sigma_um) check::positive(concat(src, ": sigma_um"), *request.sigma_um, " µm");
    check::non_negative(concat(src, ": sigma_um_stderr"), request.sigma_um_stderr, " µm");
    for (std::size_t k = 0; k < request.captures.size(); ++k) {
        const CaptureSpec& spec = request.captures[k];
        const std::string name = concat(src, ": captures[", std::to_string(k), "]");
        if (spec.image.empty()) throw InvalidArgument(concat(name, ": no image file given"));
        if (spec.bracket.size() == 1)
            throw InvalidArgument(concat(name, ": a bracket needs at least 2 photographs"));
        for (const BracketShot& shot : spec.bracket)
            check::positive(concat(name, ": ", shot.image, ": exposure_s"), shot.exposure_s, " s");
        check::polar_angle(concat(name, ": theta_i"), spec.geometry.theta_i_rad);
        check::polar_angle(concat(name, ": theta_s"), spec.geometry.theta_s_rad);
        check::azimuth(concat(name, ": phi_s"), spec.geometry.phi_s_rad);
        if (spec.exposure_s &&
            !(*spec.exposure_s >= kMinExposureS && *spec.exposure_s <= kMaxExposureS))
            throw InvalidArgument(concat(name,
                                         ": exposure_s = ", check::format_number(*spec.exposure_s),
                                         " s must be in [", check::format_number(kMinExposureS),
                                         ", ", check::format_number(kMaxExposureS), "] s"));
    }
    check_combination(request);
    detail::check_tolerances(request);
    detail::check_finite_distance(request);
}

// What the captures, the object and the maps ask for together. A capture file's combination
// that cannot be measured is its error (DataError naming the file and the key); a request built
// in code gets InvalidArgument.
void check_combination(const MeasureRequest& request) {
    const std::string src = where(request);
    auto refuse = [&](std::string_view key, const std::string& reason) {
        if (request.source.empty()) throw InvalidArgument(concat(src, ": ", reason));
        throw DataError(concat(src, ": ", key, ": ", reason));
    };
    const auto diffuse =
        std::count_if(request.captures.begin(), request.captures.end(),
                      [](const CaptureSpec& s) { return s.role == CaptureRole::Diffuse; });
    const auto specular = static_cast<std::ptrdiff_t>(request.captures.size()) - diffuse;
    const ObjectShape shape = request.object.shape;
    if (is_profile(shape)) {
        if (request.captures.size() != 1 || specular != 0)
            refuse("captures", concat("a ", to_string(shape),
                                      " is measured from one diffuse photograph (§5.2); got ",
                                      std::to_string(request.captures.size()), " captures (",
                                      std::to_string(specular), " specular)"));
        if (request.maps)
            refuse("maps", concat("maps are made of a flat sample or an object with a normal map "
                                  "(object.shape plane or normal_map), not of a ",
                                  to_string(shape)));
        return;
    }
    if (shape == ObjectShape::PhotometricStereo) {
        detail::check_photometric_stereo_request(request, refuse);
        return;
    }
    if (request.maps && diffuse < 2)
        refuse("maps", concat("a roughness map needs two diffuse captures (lit from two "
                              "directions); got ",
                              std::to_string(diffuse)));
    if (shape == ObjectShape::NormalMap && !request.maps)
        refuse("object.shape", "normal_map is measured as a map: give \"maps\"");
    if (!request.roi && !request.maps) refuse("roi", "missing: give the region to measure");
    if (diffuse == 1 && specular == 0)
        refuse("captures",
               "one diffuse capture gives no estimate; give a second diffuse capture at another "
               "light or view direction, or a specular capture");
}

// The exposure time of a capture: the capture file's, else the metadata's (0: unknown).
double exposure_time(const CaptureMeasurement& c, std::string& source) {
    if (c.spec.exposure_s) {
        source = "capture file";
        return *c.spec.exposure_s;
    }
    if (c.info.exposure_s && *c.info.exposure_s > 0.0) {
        source = "metadata";
        return *c.info.exposure_s;
    }
    return 0.0;
}

// "exposures_equal": every capture's time scale is 1; a time that differs from another one
// contradicts it (a DataError naming both).
void assign_equal_exposures(std::vector<CaptureMeasurement>& captures, const std::string& src) {
    const CaptureMeasurement* timed = nullptr;
    double first_time = 0.0;
    for (auto& c : captures) {
        std::string source;
        const double t = c.spec.bracket.empty() ? exposure_time(c, source) : 0.0;
        if (t > 0.0 && timed == nullptr) {
            timed = &c;
            first_time = t;
        } else if (t > 0.0 && std::abs(t - first_time) > 1e-6 * first_time) {
            throw DataError(concat(src, ": exposures_equal: true, but ", c.spec.image, " has ",
                                   check::format_number(t), " s (", source, ") and ",
                                   timed->spec.image, " ", check::format_number(first_time),
                                   " s; give each capture's exposure_s and leave "
                                   "exposures_equal out"));
        }
        c.exposure_scale = 1.0;
        c.exposure_source = "equal (exposures_equal)";
    }
}

// The exposure scale s_k of every capture (measure.hpp) and where its time came from. Captures
// compared with each other (two diffuse ones or more) need their times: from the capture file or
// the metadata, or "exposures_equal"; without any, a ratio of brightness would be off by the
// ratio of the unknown exposures, so the request is refused.
void assign_exposures(std::vector<CaptureMeasurement>& captures, bool exposures_equal,
                      const std::string& src) {
    std::size_t known = 0;
    for (auto& c : captures) {
        const double t = exposure_time(c, c.exposure_source);
        if (t > 0.0) {
            c.exposure_scale = t;
            ++known;
        }
    }
    const auto compared = std::count_if(
        captures.begin(), captures.end(),
        [](const CaptureMeasurement& c) { return c.spec.role == CaptureRole::Diffuse; });
    if (exposures_equal) {
        assign_equal_exposures(captures, src);
    } else if (known == 0) {
        if (compared >= 2)
            throw DataError(concat(src,
                                   ": exposures_equal: no capture gives an exposure time "
                                   "(exposure_s in the capture file, or EXIF/RAW metadata), so "
                                   "their brightness cannot be compared; give each capture's "
                                   "exposure_s, or \"exposures_equal\": true when every "
                                   "photograph was taken with the same exposure"));
        for (auto& c : captures) {
            c.exposure_scale = 1.0;
            c.exposure_source = "not needed (one capture compared)";
        }
        return;
    }
    if (!exposures_equal && known < captures.size()) {
        // Only the diffuse captures are compared with each other: a specular capture's σ comes
        // from a ratio within the one image (Eq. 13) and needs no exposure time.
        for (auto& c : captures)
            if (c.exposure_source.empty() && c.spec.role == CaptureRole::Specular) {
                c.exposure_scale = 1.0;
                c.exposure_source = "not needed (specular)";
            }
        for (std::size_t k = 0; k < captures.size(); ++k)
            if (captures[k].exposure_source.empty())
                throw DataError(concat(src, ": captures[", std::to_string(k),
                                       "].exposure_s: ", captures[k].spec.image,
                                       " has no exposure time (none given, none in its "
                                       "metadata) while others have one; give exposure_s for "
                                       "it"));
    }
    // ISO and f-number: used when every capture's metadata gives them (s ∝ t · ISO / N²).
    const bool all_iso = std::all_of(captures.begin(), captures.end(),
                                     [](const auto& c) { return c.info.iso && *c.info.iso > 0.0; });
    const bool all_f = std::all_of(captures.begin(), captures.end(), [](const auto& c) {
        return c.info.f_number && *c.info.f_number > 0.0;
    });
    for (auto& c : captures) {
        if (all_iso) c.exposure_scale *= *c.info.iso / *captures.front().info.iso;
        if (all_f) {
            const double ratio = *captures.front().info.f_number / *c.info.f_number;
            c.exposure_scale *= ratio * ratio;
        }
    }
}

using detail::check_same_recording;
using detail::check_same_size;
using detail::check_same_size_pixels;
using detail::code_scale;
using detail::keyed;
using detail::Loader;

// σ per channel from one specular capture (Eq. 13, with each channel's λ) and from the RGB
// average (λ of the request); their agreement as χ² about the weighted mean.
void estimate_specular(const CaptureMeasurement& capture, const MeasureRequest& request,
                       MeasureResult& result) {
    const HighlightMeasurement& h = *capture.highlight;
    const Geometry& g = capture.spec.geometry;
    const std::size_t channels = h.core.channels.size();
    auto one = [&](const ChannelStatistics& tot, const ChannelStatistics& dif, double lambda_um,
                   std::string channel) {
        SpecularInput input;
        input.E_tot = tot.mean;
        input.E_dif = dif.mean;
        input.theta_rad = g.theta_i_rad;
        input.wavelength_um = lambda_um;
        input.R0 = request.R0;
        input.relative_noise_tot = relative_stderr(tot);
        input.relative_noise_dif = relative_stderr(dif);
        ChannelSigma cs;
        cs.channel = std::move(channel);
        cs.wavelength_um = lambda_um;
        cs.estimate = estimate_sigma_specular(input);
        return cs;
    };
    if (channels == 3) {
        static constexpr std::array<const char*, 3> kNames{"R", "G", "B"};
        for (std::size_t c = 0; c < 3; ++c) {
            try {
                result.specular_sigma.push_back(one(h.core.channels[c], h.annulus.channels[c],
                                                    request.channel_wavelengths_um[c], kNames[c]));
            } catch (const Error& e) {
                result.warnings.push_back(
                    concat(capture.spec.image, ": channel ", kNames[c], ": no σ: ", e.what()));
            }
        }
    }
    ChannelSigma average = one(h.core.average, h.annulus.average, request.wavelength_um,
                               channels == 3 ? "average" : "grey");
    result.sigma = average.estimate;
    result.specular_sigma.push_back(std::move(average));
    // Channel agreement: χ² of the per-channel σ about their inverse-variance weighted mean.
    if (channels == 3 && result.specular_sigma.size() == 4) {
        double sw = 0.0, swx = 0.0;
        bool have_errors = true;
        for (std::size_t c = 0; c < 3; ++c) {
            const Estimate& s = *result.specular_sigma[c].estimate.sigma_um;
            if (!(s.std_error > 0.0)) have_errors = false;
            if (!have_errors) break;
            const double w = 1.0 / (s.std_error * s.std_error);
            sw += w;
            swx += w * s.value;
        }
        if (have_errors) {
            const double mean = swx / sw;
            double chi2 = 0.0;
            for (std::size_t c = 0; c < 3; ++c) {
                const Estimate& s = *result.specular_sigma[c].estimate.sigma_um;
                chi2 += (s.value - mean) * (s.value - mean) / (s.std_error * s.std_error);
            }
            result.channel_sigma_chi2 = chi2;
            result.channel_sigma_dof = 2;
            // χ²(2) exceeds 9.21 with probability 1 %.
            if (chi2 > 9.21)
                result.warnings.push_back(concat(
                    capture.spec.image,
                    ": σ differs between the R, G and B channels beyond their "
                    "standard errors (χ² = ",
                    check::format_number(chi2),
                    " with 2 degrees of freedom): the σ–λ scaling of Eq. 13 does not hold; check "
                    "the channel wavelengths, the response and the highlight regions"));
        }
    }
}

// σ known (given or from a specular capture); sigma_stderr_known false when the specular
// capture could not give its standard error.
struct KnownSigma {
    std::optional<double> value;
    double stderr_um = 0.0;
    bool stderr_known = true;
};

// The standard errors that rest on a brightness whose noise the region cannot give (a standard
// error of exactly 0: one pixel, or no spread between its pixels) are unknown, not 0
// (measure.hpp): NaN, with a warning naming the capture.
void mark_unknown_diffuse_errors(const CaptureMeasurement& c1, const CaptureMeasurement& c2,
                                 const std::string& src, bool sigma_stderr_known,
                                 MeasureResult& result) {
    bool ratio_known = true;
    for (const CaptureMeasurement* c : {&c1, &c2}) {
        if (c->brightness_relative_stderr > 0.0) continue;
        ratio_known = false;
        result.warnings.push_back(
            concat(src, ": ", c->spec.image, ": the region's brightness has no measurable noise (",
                   std::to_string(c->region.average.count),
                   " pixel(s) used, standard error 0): the standard errors of E1/E2, σ/T and T are "
                   "unknown (null)"));
    }
    if (!ratio_known) {
        detail::mark_unknown(result.E1_over_E2);
        for (auto* e :
             {&result.slope_gaussian, &result.slope_exponential, &result.correlation_length})
            if (*e) detail::mark_unknown_errors(**e, false);
    }
    if (!sigma_stderr_known) {
        // T = σ/(σ/T) and T given σ carry σ's unknown error.
        for (auto* e : {&result.slope_gaussian, &result.slope_exponential})
            if (*e) detail::mark_unknown((*e)->T_um);
        if (result.correlation_length)
            detail::mark_unknown_errors(*result.correlation_length, true);
    }
}

void estimate_diffuse(const std::vector<CaptureMeasurement*>& diffuse,
                      const MeasureRequest& request, const KnownSigma& known,
                      MeasureResult& result) {
    CaptureMeasurement& c1 = *diffuse[0];
    CaptureMeasurement& c2 = *diffuse[1];
    const std::optional<double>& sigma_um = known.value;
    const double sigma_um_stderr = known.stderr_um;
    const double ratio = c1.brightness / c2.brightness;
    const double e1 = c1.brightness_relative_stderr;
    const double e2 = c2.brightness_relative_stderr;
    result.E1_over_E2 = Estimate{ratio, ratio * std::hypot(e1, e2)};

    TwoGeometryOptions options;
    options.factor = request.factor;
    options.radiometry = request.radiometry;
    options.wavelength_um = request.wavelength_um;
    if (sigma_um) {
        options.regime = detail::correlation_length_regime(
            request.regime, *sigma_um, c1.spec.geometry, c2.spec.geometry, request.wavelength_um);
        result.correlation_length_regime = options.regime;
        result.correlation_length_regime_given = request.regime.has_value();
        const double g =
            detail::largest_g(*sigma_um, c1.spec.geometry, c2.spec.geometry, request.wavelength_um);
        if (!request.regime && options.regime != Regime::SlightlyRough)
            result.warnings.push_back(concat(
                "T given σ: g = ", format_significant(g, 4, "g"),
                " (the larger of the two captures) is beyond the slightly rough range g < ",
                check::format_number(kSlightlyRoughMaxG),
                " of the paper's Eq. 15: T is from the exact series of the diffuse term (regime "
                "\"series\"); \"regime\": \"slightly_rough\" in the capture file gives Eq. 15"));
    }
    std::vector<std::string> failures;
    for (const Correlation correlation : {Correlation::Gaussian, Correlation::Exponential}) {
        SlopeInput input;
        input.E1_over_E2 = ratio;
        input.geom1 = c1.spec.geometry;
        input.geom2 = c2.spec.geometry;
        input.correlation = correlation;
        input.options = options;
        input.noise = BrightnessNoise{e1, e2};
        input.sigma_um = sigma_um;
        try {
            // A lamp or camera at a finite distance: the ratio at the nominal geometries.
            const detail::CorrectionModel model{correlation == Correlation::Gaussian
                                                    ? detail::CorrectedQuantity::SlopeGaussian
                                                    : detail::CorrectedQuantity::SlopeExponential,
                                                correlation, options, 0.0};
            input.E1_over_E2 = detail::corrected_ratio(
                ratio, model,
                [&](double r) {
                    SlopeInput i = input;
                    i.E1_over_E2 = r;
                    return estimate_slope(i).sigma_over_T.value().value;
                },
                c1, c2);
            RoughnessEstimate estimate = estimate_slope(input);
            (correlation == Correlation::Gaussian ? result.slope_gaussian
                                                  : result.slope_exponential) = std::move(estimate);
        } catch (const NoSolution& e) {
            failures.push_back(concat("σ/T (", to_string(correlation), "): ", e.what()));
        }
    }
    if (sigma_um) {
        CorrelationLengthInput input;
        input.E1_over_E2 = ratio;
        input.sigma_um = *sigma_um;
        input.sigma_um_std_error = sigma_um_stderr;
        input.geom1 = c1.spec.geometry;
        input.geom2 = c2.spec.geometry;
        input.correlation = request.correlation;
        input.options = options;
        input.noise = BrightnessNoise{e1, e2};
        try {
            const detail::CorrectionModel model{detail::CorrectedQuantity::CorrelationLength,
                                                request.correlation, options, *sigma_um};
            input.E1_over_E2 = detail::corrected_ratio(
                ratio, model,
                [&](double r) {
                    CorrelationLengthInput i = input;
                    i.E1_over_E2 = r;
                    return estimate_correlation_length(i).T_um.value().value;
                },
                c1, c2);
            result.correlation_length = estimate_correlation_length(input);
        } catch (const NoSolution& e) {
            failures.push_back(concat("T given σ: ", e.what()));
            result.correlation_length_regime.reset();
        }
    }
    if (!result.slope_gaussian && !result.slope_exponential && !result.correlation_length) {
        std::string message =
            concat(where(request), ": E1/E2 = ", check::format_number(ratio), " of ", c1.spec.image,
                   " and ", c2.spec.image, " has no solution:");
        for (const auto& f : failures) message = concat(message, " ", f, ";");
        throw NoSolution(message);
    }
    for (const auto& f : failures) result.warnings.push_back(concat(where(request), ": ", f));
    mark_unknown_diffuse_errors(c1, c2, where(request), known.stderr_known, result);
    // The warnings of the estimates behind the headline values (σ/T Gaussian gives θK, ξK and
    // the slope; T given σ): the exponential estimate keeps its own in its object.
    const std::array<std::pair<const char*, const std::optional<RoughnessEstimate>*>, 2> estimates{
        {{"σ/T", &result.slope_gaussian}, {"T given σ", &result.correlation_length}}};
    for (const auto& [label, estimate] : estimates)
        if (*estimate)
            for (const auto& w : (*estimate)->warnings)
                result.warnings.push_back(concat(label, ": ", w));

    if (diffuse.size() >= 3 && c1.finite_distance) {
        FitOptions fit_options;
        fit_options.factor = request.factor;
        fit_options.radiometry = request.radiometry;
        fit_options.wavelength_um = request.wavelength_um;
        auto slope = [](const std::optional<RoughnessEstimate>& e) {
            return e && e->sigma_over_T ? std::optional(e->sigma_over_T->value) : std::nullopt;
        };
        result.fit = detail::fit_corrected(
            diffuse, fit_options, {slope(result.slope_gaussian), slope(result.slope_exponential)});
    } else if (diffuse.size() >= 3) {
        std::vector<Measurement> measurements;
        for (const CaptureMeasurement* c : diffuse) {
            Measurement m;
            m.geometry = c->spec.geometry;
            m.brightness = c->brightness;
            const double e = c->brightness_relative_stderr;
            m.weight = e > 0.0 ? 1.0 / (e * e) : 1.0;
            measurements.push_back(m);
        }
        FitOptions fit_options;
        fit_options.factor = request.factor;
        fit_options.radiometry = request.radiometry;
        fit_options.wavelength_um = request.wavelength_um;
        result.fit = compare_correlations(measurements, fit_options);
    }
}

}  // namespace

std::string_view to_string(CaptureRole role) { return name_of(kRoleNames, role); }

CaptureRole parse_capture_role(std::string_view name) {
    return parse_name(kRoleNames, "capture role", name);
}

std::string_view to_string(ObjectShape shape) { return name_of(kShapeNames, shape); }

ObjectShape parse_object_shape(std::string_view name) {
    return parse_name(kShapeNames, "object shape", name);
}

namespace {

// The normals of a normal-map image (ObjectSpec::normal_map): 3 floats per pixel, NaN off the
// object. Every finite normal is used: the reader's flags for light (a component at or below 0
// is "clipped low", at or above 1 "saturated") say nothing about a direction; only a missing
// sample (NaN in a float file) and a vector shorter than 0.5 (the usual off-object marker, e.g.
// (0, 0, 0)) are off the object.
std::vector<float> decode_normal_map(const LinearImage& image, const std::string& src) {
    if (image.channels != 3)
        throw DataError(concat(src, ": normal map ", image.info.source, " has ",
                               std::to_string(image.channels),
                               " channel(s); a normal map holds 3 (n_x, n_y, n_z as R, G, B)"));
    const bool encoded = !image.info.is_float;  // integer files: n = 2v − 1
    const std::size_t n = image.pixel_count();
    std::vector<float> normals(3 * n);
    for (std::size_t k = 0; k < n; ++k) {
        double v[3];
        for (std::size_t c = 0; c < 3; ++c) {
            const double x = image.values[c * n + k];
            v[c] = encoded ? 2.0 * x - 1.0 : x;
        }
        const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        const bool missing = !image.flags.empty() && (image.flags[k] & kPixelMissing) != 0;
        const bool on = !missing && norm >= 0.5;
        for (std::size_t c = 0; c < 3; ++c)
            normals[3 * k + c] =
                on ? static_cast<float>(v[c] / norm) : std::numeric_limits<float>::quiet_NaN();
    }
    return normals;
}

// One int32 per pixel: the index of the first named region that holds the pixel, else −1.
std::vector<std::int32_t> region_labels(const MapRequest& maps, std::size_t width,
                                        std::size_t height) {
    std::vector<std::int32_t> labels(width * height, -1);
    for (std::size_t r = 0; r < maps.regions.size(); ++r) {
        const std::vector<std::uint8_t> mask = rasterize(maps.regions[r].second, width, height);
        for (std::size_t k = 0; k < mask.size(); ++k)
            if (mask[k] != 0 && labels[k] < 0) labels[k] = static_cast<std::int32_t>(r);
    }
    return labels;
}

// Captures in flight by default (threads = 0): each holds its decoded image.
constexpr std::size_t kMaxDefaultThreads = 4;

// What one capture gives: its measurement, its warnings (in order), the curved object's profile,
// the image itself when a map divides it, or the error that stopped it.
struct CaptureOutcome {
    CaptureMeasurement capture;
    std::vector<std::string> warnings;
    std::optional<CylinderProfile> cylinder;
    std::optional<SphereResult> sphere;
    std::optional<LinearImage> map_image;
    std::exception_ptr error;
};

// The first capture's size (a LinearImage without values) and the region, which every capture
// is measured with: as spans, and as a mask for the measurements that take one (a highlight, a
// cylinder, a sphere).
struct FirstCapture {
    LinearImage header;
    RegionSpans spans;
    RegionSpans black_spans;  // the black reference's, when given
    std::vector<std::uint8_t> mask;
};

// The captures measured by up to `threads` workers, each taking the next capture in order (so
// capture 0, which gives the size and the mask, is always taken first and never waits). Every
// capture's result is what a one-thread run gives; the first failing capture's error is thrown.
class CaptureRun {
  public:
    CaptureRun(const MeasureRequest& request, const Loader& loader,
               const std::optional<LinearImage>& dark, const std::optional<LinearImage>& flat)
        : request_(request),
          loader_(loader),
          dark_(dark),
          flat_(flat),
          outcomes_(request.captures.size()),
          first_ready_(first_.get_future().share()) {
        // Photometric stereo solves with every capture; a map divides the first two diffuse.
        if (request.object.shape == ObjectShape::PhotometricStereo)
            for (std::size_t k = 0; k < request.captures.size(); ++k) map_keep_.push_back(k);
        else if (request.maps)
            for (std::size_t k = 0; k < request.captures.size() && map_keep_.size() < 2; ++k)
                if (request.captures[k].role == CaptureRole::Diffuse) map_keep_.push_back(k);
    }

    void run(std::size_t threads) {
        const std::size_t n = request_.captures.size();
        threads = std::clamp<std::size_t>(threads, 1, n);
        std::vector<std::thread> workers;
        workers.reserve(threads - 1);
        for (std::size_t t = 1; t < threads; ++t) workers.emplace_back([this] { work(); });
        work();
        for (std::thread& w : workers) w.join();
        for (const CaptureOutcome& o : outcomes_)
            if (o.error) std::rethrow_exception(o.error);
    }

    std::vector<CaptureOutcome>& outcomes() { return outcomes_; }
    const FirstCapture& first() const { return first_ready_.get(); }

    // Whether any capture is measured on the region's mask rather than its spans.
    bool needs_mask() const {
        return request_.object.shape == ObjectShape::Cylinder ||
               request_.object.shape == ObjectShape::PhotometricStereo ||
               request_.object.shape == ObjectShape::Sphere ||
               std::any_of(request_.captures.begin(), request_.captures.end(),
                           [](const CaptureSpec& c) { return c.role == CaptureRole::Specular; });
    }

  private:
    void work() {
        for (;;) {
            const std::size_t k = next_.fetch_add(1);
            if (k >= outcomes_.size()) return;
            try {
                measure_capture(k);
            } catch (...) {
                outcomes_[k].error = std::current_exception();
                if (k == 0 && !first_published_) first_.set_exception(std::current_exception());
            }
        }
    }

    // The black reference's mean, per channel, subtracted from the capture (measure.hpp).
    void subtract_black_reference(LinearImage& image, const RegionSpans& spans,
                                  CaptureMeasurement& capture) const {
        const RegionStatistics black = keyed(request_, "black_reference", [&] {
            return region_statistics(image, spans, request_.statistics);
        });
        std::vector<double> offset;
        for (const ChannelStatistics& c : black.channels) offset.push_back(c.mean);
        if (offset.size() != image.channels) offset.assign(image.channels, black.average.mean);
        subtract_offset(image, offset);
        capture.black_reference = black.average;
    }

    void measure_capture(std::size_t k) {
        const CaptureSpec& spec = request_.captures[k];
        const std::string src = where(request_);
        CaptureOutcome& out = outcomes_[k];
        CaptureMeasurement& capture = out.capture;
        capture.spec = spec;
        // A merged bracket is per second of exposure.
        if (!spec.bracket.empty()) capture.spec.exposure_s = 1.0;
        LinearImage image = loader_.capture(spec, k);
        if (k == 0) {
            FirstCapture first;
            first.header.width = image.width;
            first.header.height = image.height;
            first.header.channels = image.channels;
            first.header.info.source = image.info.source;
            if (request_.roi) {
                first.spans = keyed(request_, "roi", [&] {
                    return region_spans(*request_.roi, image.width, image.height);
                });
                if (needs_mask()) first.mask = rasterize(first.spans);
            }
            if (request_.black_reference)
                first.black_spans = keyed(request_, "black_reference", [&] {
                    return region_spans(*request_.black_reference, image.width, image.height);
                });
            first_.set_value(std::move(first));
            first_published_ = true;
        }
        // Capture 0's failure ends the others here (its error is the one thrown).
        const FirstCapture& first = first_ready_.get();
        auto image_key = [](const CaptureSpec& c, std::size_t index) {
            return concat("captures[", std::to_string(index), "]",
                          c.bracket.empty() ? ".image" : ".bracket");
        };
        const std::string first_key = image_key(request_.captures.front(), 0);
        check_same_size(image, first.header, src, image_key(spec, k), first_key);
        for (const auto& w : image.info.warnings)
            out.warnings.push_back(concat(spec.image, ": ", w));
        detail::assumption_warnings(request_, spec, image.info, out.warnings);
        // The dark frame, then the flat field: each of the captures' size and recording.
        auto correct = [&](const LinearImage& frame, const std::string& frame_key, bool dark) {
            check_same_size(frame, first.header, src, frame_key, first_key);
            if (spec.bracket.empty()) check_same_recording(frame, image, src, frame_key);
            keyed(request_, frame_key, [&] {
                if (dark)
                    subtract_dark_frame(image, frame);
                else
                    divide_flat_field(image, frame);
            });
        };
        if (dark_) correct(*dark_, "dark_frame", true);
        if (flat_) correct(*flat_, "flat_field", false);
        if (request_.black_reference) subtract_black_reference(image, first.black_spans, capture);
        const std::vector<std::uint8_t>* roi_mask = request_.roi ? &first.mask : nullptr;
        const ObjectShape shape = request_.object.shape;
        if (shape == ObjectShape::Cylinder) {
            CylinderOptions options = request_.object.cylinder;
            options.light = spec.light.value_or(Eigen::Vector3d::UnitZ());
            options.view = spec.view.value_or(Eigen::Vector3d::UnitZ());
            out.cylinder = keyed(request_, "object", [&] {
                return measure_cylinder_profile(image, roi_mask, options);
            });
            for (const auto& w : out.cylinder->warnings)
                out.warnings.push_back(concat(spec.image, ": ", w));
        } else if (shape == ObjectShape::Sphere) {
            SphereOptions options = request_.object.sphere;
            options.light = spec.light.value_or(Eigen::Vector3d::UnitZ());
            options.view = spec.view.value_or(Eigen::Vector3d::UnitZ());
            out.sphere =
                keyed(request_, "object", [&] { return measure_sphere(image, roi_mask, options); });
            for (const auto& w : out.sphere->warnings)
                out.warnings.push_back(concat(spec.image, ": ", w));
        } else if (spec.role == CaptureRole::Specular) {
            if (!request_.roi)
                throw InvalidArgument(concat(src, ": ", spec.image,
                                             ": a specular capture needs the roi that holds its "
                                             "highlight"));
            capture.highlight = keyed(request_, "highlight", [&] {
                return measure_highlight(image, first.mask, request_.highlight);
            });
            capture.region = capture.highlight->core;
            for (const auto& w : capture.highlight->warnings)
                out.warnings.push_back(concat(spec.image, ": ", w));
        } else if (request_.roi) {
            capture.region = keyed(request_, "roi", [&] {
                return region_statistics(image, first.spans, request_.statistics);
            });
            for (const auto& w : capture.region.warnings)
                out.warnings.push_back(concat(spec.image, ": ", w));
        }
        capture.info = image.info;
        if (std::find(map_keep_.begin(), map_keep_.end(), k) != map_keep_.end())
            out.map_image = std::move(image);
    }

    const MeasureRequest& request_;
    const Loader& loader_;
    const std::optional<LinearImage>& dark_;
    const std::optional<LinearImage>& flat_;
    std::vector<CaptureOutcome> outcomes_;
    std::vector<std::size_t> map_keep_;
    std::atomic<std::size_t> next_{0};
    std::promise<FirstCapture> first_;
    bool first_published_ = false;  // only the worker of capture 0 touches it
    std::shared_future<FirstCapture> first_ready_;
};

}  // namespace

MeasureResult measure(const MeasureRequest& request) {
    check_request(request);
    const std::string src = where(request);
    MeasureResult result;
    const ObjectShape shape = request.object.shape;

    const Loader loader(request);
    std::optional<LinearImage> dark, flat;
    if (request.dark_frame) dark = loader.image(*request.dark_frame, "dark_frame");
    if (request.flat_field) flat = loader.image(*request.flat_field, "flat_field");

    CaptureRun run(request, loader, dark, flat);
    run.run(request.threads == 0
                ? std::min<std::size_t>(kMaxDefaultThreads,
                                        std::max(1U, std::thread::hardware_concurrency()))
                : request.threads);
    const FirstCapture& first_capture = run.first();
    const LinearImage* first = &first_capture.header;
    result.region_pixels = first_capture.spans.pixel_count;
    // A map keeps the first two diffuse images (the pair it divides) and their captures' index.
    std::vector<LinearImage> map_images;
    std::vector<std::size_t> map_captures;
    for (CaptureOutcome& o : run.outcomes()) {
        for (auto& w : o.warnings) result.warnings.push_back(std::move(w));
        if (o.cylinder) result.cylinder = std::move(o.cylinder);
        if (o.sphere) result.sphere = std::move(o.sphere);
        if (o.map_image) {
            map_images.push_back(std::move(*o.map_image));
            map_captures.push_back(result.captures.size());
        }
        result.captures.push_back(std::move(o.capture));
    }
    assign_exposures(result.captures, request.exposures_equal, src);
    if (shape == ObjectShape::PhotometricStereo) {
        std::vector<std::int32_t> labels;
        if (request.maps && !request.maps->regions.empty())
            labels = keyed(request, "maps.regions", [&] {
                return region_labels(*request.maps, first->width, first->height);
            });
        detail::measure_photometric_stereo(request, first_capture.mask, map_images, labels, result);
        return result;
    }
    if (is_profile(shape)) {
        for (CaptureMeasurement& c : result.captures) c.brightness_relative_stderr = 0.0;
        if (detail::has_exponential_sigma_over_T(result))
            result.warnings.push_back(detail::exponential_note());
        return result;
    }
    detail::locate_captures(request, first_capture.spans, result.captures);
    std::vector<CaptureMeasurement*> diffuse;
    if (request.roi) {
        for (CaptureMeasurement& c : result.captures) {
            if (c.spec.role != CaptureRole::Diffuse) continue;
            const ChannelStatistics& avg = c.region.average;
            if (!(avg.mean > 0.0))
                throw InvalidArgument(
                    concat(src, ": ", c.spec.image, ": the region's mean brightness ",
                           check::format_number(avg.mean),
                           " is not above the black level (after the dark frame): nothing to "
                           "measure; check the exposure and the region"));
            c.brightness = avg.mean / c.exposure_scale;
            c.brightness_relative_stderr = relative_stderr(avg);
            diffuse.push_back(&c);
        }
    }

    KnownSigma known{request.sigma_um, request.sigma_um_stderr, true};
    for (const CaptureMeasurement& c : result.captures) {
        if (c.spec.role != CaptureRole::Specular) continue;
        const Geometry& g = c.spec.geometry;
        // (The capture file's parser refuses this first, echoing the angles as typed.) Degrees
        // to 15 digits: 30° through radians prints as 30, not 29.999999999999996.
        if (std::abs(g.theta_i_rad - g.theta_s_rad) > kSpecularToleranceRad ||
            std::abs(std::remainder(g.phi_s_rad, 2 * kPi)) > kSpecularToleranceRad)
            throw InvalidArgument(
                concat(src, ": ", c.spec.image,
                       ": a specular capture must be taken in the specular "
                       "direction (theta_s = theta_i, phi_s = 0); got theta_i = ",
                       format_message(rad_to_deg(g.theta_i_rad), 15),
                       "°, theta_s = ", format_message(rad_to_deg(g.theta_s_rad), 15),
                       "°, phi_s = ", format_message(rad_to_deg(g.phi_s_rad), 15), "°"));
        estimate_specular(c, request, result);
        // A highlight whose core or surround has no measurable noise gives σ with a standard
        // error of 0: unknown (measure.hpp).
        const auto zero_error = [](const RoughnessEstimate& e) {
            return e.sigma_um && !(e.sigma_um->std_error > 0.0);
        };
        for (ChannelSigma& cs : result.specular_sigma)
            if (zero_error(cs.estimate)) detail::mark_unknown_errors(cs.estimate, true);
        if (result.sigma && zero_error(*result.sigma)) {
            detail::mark_unknown_errors(*result.sigma, true);
            result.warnings.push_back(concat(src, ": ", c.spec.image,
                                             ": the highlight's core or surround has no "
                                             "measurable noise (standard error 0): the standard "
                                             "error of σ is unknown (null)"));
        }
        break;  // the first specular capture gives σ
    }
    if (!known.value && result.sigma && result.sigma->sigma_um) {
        known.value = result.sigma->sigma_um->value;
        known.stderr_um = result.sigma->sigma_um->std_error;
        // Not a number (unknown, measure.hpp): T's error leaves σ's out and is unknown too.
        if (!(known.stderr_um > 0.0)) {
            known.stderr_um = 0.0;
            known.stderr_known = false;
        }
    }
    if (diffuse.size() >= 2) estimate_diffuse(diffuse, request, known, result);
    result.uncertainty = uncertainty_budget(request, result);
    if (result.uncertainty)
        for (const auto& w : result.uncertainty->warnings) result.warnings.push_back(w);
    result.exact_series = exact_series_estimate(request, result);
    if (result.exact_series)
        for (const auto& w : result.exact_series->warnings) result.warnings.push_back(w);

    if (request.maps) {
        MapOptions options = request.maps->options;
        options.factor = request.factor;
        options.radiometry = request.radiometry;
        options.wavelength_um = request.wavelength_um;
        options.correlation = request.correlation;
        if (known.value) {
            options.sigma_um = known.value;
            options.sigma_um_stderr = known.stderr_um;
        }
        std::vector<float> normals;
        if (shape == ObjectShape::NormalMap) {
            // Read as stored (linear, no black level): the values encode directions, not light.
            const LinearImage normal_image = keyed(request, "object.file", [&] {
                return read_image(request.object.normal_map, code_scale());
            });
            check_same_size_pixels(normal_image, *first, src, "object.file");
            normals = decode_normal_map(normal_image, src);
            options.normal_map = normals;
        }
        std::vector<std::int32_t> labels;
        if (!request.maps->regions.empty()) {
            labels = keyed(request, "maps.regions", [&] {
                return region_labels(*request.maps, first->width, first->height);
            });
            options.region_labels = labels;
            for (const auto& r : request.maps->regions) options.region_names.push_back(r.first);
        }
        std::vector<MapCapture> captures;
        for (std::size_t k = 0; k < map_images.size(); ++k) {
            const CaptureMeasurement& c = result.captures[map_captures[k]];
            MapCapture m;
            m.image = &map_images[k];
            m.name = c.spec.image;
            m.geometry = c.spec.geometry;
            m.exposure_scale = c.exposure_scale;
            m.light = c.spec.light;
            m.view = c.spec.view;
            if (shape == ObjectShape::NormalMap) {
                if (!m.light) m.light = light_direction(c.spec.geometry);
                if (!m.view) m.view = view_direction(c.spec.geometry);
            }
            captures.push_back(std::move(m));
        }
        const auto diffuse_count =
            std::count_if(request.captures.begin(), request.captures.end(),
                          [](const CaptureSpec& s) { return s.role == CaptureRole::Diffuse; });
        if (diffuse_count > 2)
            result.warnings.push_back(concat(src,
                                             ": the map divides the first two diffuse captures; "
                                             "the others enter the region measurement only"));
        result.map = keyed(request, "maps", [&] { return roughness_map(captures, options); });
        if (detail::has_position(request))
            result.warnings.push_back(
                concat(src,
                       ": the map uses each capture's geometry at the region's centroid: a lamp or "
                       "camera at a finite distance is corrected in the region's estimates only"));
        for (const auto& w : result.map->warnings) result.warnings.push_back(concat("map: ", w));
    }
    if (detail::has_exponential_sigma_over_T(result))
        result.warnings.push_back(detail::exponential_note());
    // Each warning once, in the order first given.
    std::vector<std::string> unique;
    for (auto& w : result.warnings)
        if (std::find(unique.begin(), unique.end(), w) == unique.end())
            unique.push_back(std::move(w));
    result.warnings = std::move(unique);
    return result;
}

}  // namespace roughscope::image
