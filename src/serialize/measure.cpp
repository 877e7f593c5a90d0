// A measurement from photographs as JSON (serialize/measure.hpp).
#include "roughscope/serialize/measure.hpp"

#include <string>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/serialize/comparison.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/photometric_stereo.hpp"

namespace roughscope::serialize {
namespace {

Json channel_json(const image::ChannelStatistics& s) {
    Json out;
    out["mean"] = number(s.mean);
    out["robust_mean"] = number(s.robust_mean);
    out["std"] = number(s.std_dev);
    out["stderr_pixel"] = number(s.stderr_pixel);
    out["stderr_tiles"] = number(s.stderr_tiles);
    out["count"] = s.count;
    out["tiles"] = s.tiles;
    return out;
}

void put(Json& out, const std::string& key, const std::optional<Estimate>& e) {
    out[key] = e ? number(e->value) : Json();
    out[key + "_stderr"] = e ? number(e->std_error) : Json();
}

std::optional<Estimate> degrees_of(const std::optional<Estimate>& e) {
    if (!e) return std::nullopt;
    return Estimate{rad_to_deg(e->value), rad_to_deg(e->std_error)};
}

Json optional_estimate(const std::optional<RoughnessEstimate>& e) {
    return e ? to_json(*e, true) : Json();
}

Json capture_json(const image::CaptureMeasurement& c) {
    Json out;
    out["image"] = c.spec.image;
    out["role"] = std::string(image::to_string(c.spec.role));
    out["theta_i_deg"] = degrees(c.spec.geometry.theta_i_rad);
    out["theta_s_deg"] = degrees(c.spec.geometry.theta_s_rad);
    out["phi_s_deg"] = degrees(c.spec.geometry.phi_s_rad);
    out["exposure_scale"] = number(c.exposure_scale);
    out["exposure_source"] = c.exposure_source;
    // The photograph's metadata: a few keys of its ImageInfo beside the capture (the metadata's
    // exposure, ISO and f-number named apart from the capture file's), all of it under `info`.
    const Json info = to_json(c.info);
    for (const char* key :
         {"format", "bits_per_sample", "response", "file_response", "file_response_evidence"})
        out[key] = info[key];
    out["exposure_s_metadata"] = info["exposure_s"];
    out["iso_metadata"] = info["iso"];
    out["f_number_metadata"] = info["f_number"];
    out["info"] = info;
    if (c.spec.role == image::CaptureRole::Diffuse) {
        out["brightness"] = number(c.brightness);
        // 0: the region gives no noise (one pixel, no spread): unknown (image/measure.hpp).
        out["brightness_relative_stderr"] =
            c.brightness_relative_stderr > 0.0 ? number(c.brightness_relative_stderr) : Json();
    } else {
        out["brightness"] = Json();
        out["brightness_relative_stderr"] = Json();
    }
    out["region"] = to_json(c.region);
    out["black_reference"] = c.black_reference ? channel_json(*c.black_reference) : Json();
    // Only with a lamp or camera position (a capture file without one writes what it did).
    if (c.finite_distance) {
        const image::FiniteDistance& fd = *c.finite_distance;
        auto optional_number = [](const std::optional<double>& v) {
            return v ? number(*v) : Json();
        };
        Json f;
        f["centroid_mm"] = Json::array(
            {number(fd.centroid_mm.x()), number(fd.centroid_mm.y()), number(fd.centroid_mm.z())});
        f["lamp_distance_mm"] = optional_number(fd.lamp_distance_mm);
        f["camera_distance_mm"] = optional_number(fd.camera_distance_mm);
        f["theta_i_deg_range"] =
            Json::array({number(fd.theta_i_min_deg), number(fd.theta_i_max_deg)});
        f["theta_s_deg_range"] =
            Json::array({number(fd.theta_s_min_deg), number(fd.theta_s_max_deg)});
        f["sample_points"] = fd.point_geometry.size();
        f["correction_sigma_over_T_gaussian"] = optional_number(fd.correction_gaussian);
        f["correction_sigma_over_T_exponential"] = optional_number(fd.correction_exponential);
        f["correction_T"] = optional_number(fd.correction_T);
        out["finite_distance"] = f;
    }
    if (c.highlight) {
        const image::HighlightMeasurement& h = *c.highlight;
        Json hj;
        hj["centre_px"] = Json::array({number(h.centre_x_px), number(h.centre_y_px)});
        hj["width_px"] = number(h.width_px);
        hj["core_radius_px"] = number(h.core_radius_px);
        hj["annulus_inner_px"] = number(h.annulus_inner_px);
        hj["annulus_outer_px"] = number(h.annulus_outer_px);
        hj["E_tot"] = number(h.E_tot);
        hj["E_tot_relative_stderr"] = number(h.E_tot_relative_stderr);
        hj["E_dif"] = number(h.E_dif);
        hj["E_dif_relative_stderr"] = number(h.E_dif_relative_stderr);
        hj["R_spec"] = h.E_tot > 0.0 ? number(1.0 - h.E_dif / h.E_tot) : Json();
        hj["core"] = to_json(h.core);
        hj["annulus"] = to_json(h.annulus);
        out["highlight"] = hj;
    } else {
        out["highlight"] = Json();
    }
    return out;
}

Json vector_json(const Eigen::Vector3d& v) {
    return Json::array({number(v.x()), number(v.y()), number(v.z())});
}

Json degrees_or_null(const std::optional<double>& radians) {
    return radians ? degrees(*radians) : Json();
}

Json profile_fit_json(const image::ProfileFit& f) {
    Json out;
    out["correlation"] = std::string(to_string(f.correlation));
    out["status"] = std::string(to_string(f.status));
    out["message"] = f.message;
    out["sigma_over_T"] = number(f.sigma_over_T);
    out["sigma_over_T_stderr"] =
        f.sigma_over_T && f.sigma_over_T_stderr > 0.0 ? number(f.sigma_over_T_stderr) : Json();
    out["gain"] = number(f.gain);
    out["aic"] = number(f.aic);
    out["bins"] = f.bins;
    return out;
}

}  // namespace

Json to_json(const image::ImageInfo& info) {
    Json out;
    out["source"] = info.source;
    out["format"] = info.format;
    out["raw_format"] = text_or_null(info.raw_format);
    out["bits_per_sample"] = info.bits_per_sample;
    out["is_float"] = info.is_float;
    out["white_level_dn"] = number(info.white_level_dn);
    out["black_level_dn"] = numbers(info.black_level_dn);
    out["response"] = std::string(to_string(info.response));
    out["gamma"] = info.response == Response::Gamma ? number(info.gamma) : Json();
    out["file_response"] =
        info.file_response ? Json(std::string(to_string(*info.file_response))) : Json();
    out["file_response_evidence"] = text_or_null(info.file_response_evidence);
    out["exposure_s"] = number(info.exposure_s);
    out["f_number"] = number(info.f_number);
    out["iso"] = number(info.iso);
    out["warnings"] = info.warnings;
    return out;
}

Json to_json(const image::CylinderProfile& p) {
    Json out;
    Json axis;
    axis["point_px"] = Json::array({number(p.axis.point_x_px), number(p.axis.point_y_px)});
    axis["direction"] = Json::array({number(p.axis.direction_x), number(p.axis.direction_y)});
    axis["radius_px"] = number(p.axis.radius_px);
    axis["source"] = p.axis.detected ? "detected" : "given";
    axis["rms_residual_px"] = p.axis.detected ? number(p.axis.rms_residual_px) : Json();
    out["axis"] = axis;
    out["light"] = vector_json(p.light);
    out["view"] = vector_json(p.view);
    out["half"] = std::string(image::to_string(p.half));
    out["bin_width_deg"] = degrees(p.bin_width_rad);
    out["maximum"] = number(p.maximum);
    Json rows = Json::array();
    for (const image::ProfileBin& b : p.bins) {
        Json row;
        row["theta_deg"] = degrees(b.theta_i_rad);
        row["theta_s_deg"] = degrees(b.geometry.theta_s_rad);
        row["phi_s_deg"] = degrees(b.geometry.phi_s_rad);
        row["alpha_deg"] = degrees(b.alpha_rad);
        row["brightness"] = number(b.brightness);
        row["stderr"] = number(b.standard_error);
        row["count"] = b.count;
        row["in_fit"] = b.in_fit;
        rows.push_back(row);
    }
    out["profile"] = rows;
    put(out, "sigma_over_T_gaussian",
        p.gaussian_fit.sigma_over_T
            ? std::optional<Estimate>(
                  Estimate{*p.gaussian_fit.sigma_over_T, p.gaussian_fit.sigma_over_T_stderr})
            : std::nullopt);
    put(out, "sigma_over_T_exponential",
        p.exponential_fit.sigma_over_T
            ? std::optional<Estimate>(
                  Estimate{*p.exponential_fit.sigma_over_T, p.exponential_fit.sigma_over_T_stderr})
            : std::nullopt);
    out["preferred_correlation"] = std::string(to_string(p.preferred));
    out["fit"] = Json{{"gaussian", profile_fit_json(p.gaussian_fit)},
                      {"exponential", profile_fit_json(p.exponential_fit)}};
    Json models = Json::array();
    Json departure;
    for (const image::ProfileModelCurve& m : p.models) {
        Json mj;
        mj["model"] = m.name;
        mj["display_name"] = std::string(image::display_name(m.model));
        mj["sigma_over_T"] = number(m.sigma_over_T);
        mj["prediction"] = numbers(m.prediction);
        mj["rms_difference"] = number(m.rms_difference);
        mj["departure_angle_deg"] = degrees_or_null(m.departure_theta_i_rad);
        departure[m.name] = mj["departure_angle_deg"];
        models.push_back(mj);
    }
    out["models"] = models;
    out["departure_angle_deg"] = departure;
    out["theta_K_deg"] = degrees_or_null(p.theta_K_rad);
    out["pixels_used"] = p.pixels_used;
    out["pixels_flagged"] = p.pixels_flagged;
    out["warnings"] = p.warnings;
    return out;
}

Json to_json(const image::SphereResult& s) {
    Json out;
    Json circle;
    circle["centre_x_px"] = number(s.circle.centre_x_px);
    circle["centre_y_px"] = number(s.circle.centre_y_px);
    circle["radius_px"] = number(s.circle.radius_px);
    circle["rms_residual_px"] = s.circle_detected ? number(s.circle.rms_residual_px) : Json();
    circle["source"] = s.circle_detected ? "detected" : "given";
    out["circle"] = circle;
    out["cell_px"] = s.cell_px;
    out["rows"] = s.table.size();
    out["pixels_used"] = s.pixels_used;
    out["pixels_flagged"] = s.pixels_flagged;
    out["comparison"] = to_json(s.comparison);
    out["warnings"] = s.warnings;
    return out;
}

Json to_json(const image::RoughnessMap& m) {
    Json out;
    out["width"] = m.width;
    out["height"] = m.height;
    out["window_px"] = m.window_px;
    out["image_width"] = m.image_width;
    out["image_height"] = m.image_height;
    out["method"] = m.method;
    out["valid"] = m.valid;
    out["missing"] = m.missing;
    out["no_solution"] = m.no_solution;
    // Of the other correlation: null unless both correlations' layers were made.
    out["no_solution_other_correlation"] =
        m.no_solution_other ? Json(*m.no_solution_other) : Json(nullptr);
    Json layers = Json::array();
    for (const MapLayer& layer : map_float_layers(m)) layers.push_back(layer.name);
    for (const MapClassLayer& layer : map_class_layers(m)) layers.push_back(layer.name);
    out["layer_names"] = layers;
    if (m.registration) {
        Json r;
        r["shift_x_px"] = number(m.registration->shift_x_px);
        r["shift_y_px"] = number(m.registration->shift_y_px);
        r["magnitude_px"] = number(m.registration->magnitude_px);
        r["response"] = number(m.registration->response);
        out["registration"] = r;
    } else {
        out["registration"] = Json();
    }
    Json classes = Json::array();
    for (const image::ClassStatistics& c : m.classes) {
        Json cj;
        cj["roughness_class"] = std::string(to_string(c.roughness_class));
        cj["count"] = c.count;
        cj["fraction"] = number(c.fraction);
        put(cj, "mean_sigma_over_T", c.mean_sigma_over_T);
        classes.push_back(cj);
    }
    out["classes"] = classes;
    Json regions = Json::array();
    for (const image::RegionMapStatistics& r : m.regions) {
        Json rj;
        rj["name"] = r.name;
        rj["count"] = r.count;
        rj["missing"] = r.missing;
        put(rj, "sigma_over_T_gaussian", r.mean_sigma_over_T_gaussian);
        put(rj, "sigma_over_T_exponential", r.mean_sigma_over_T_exponential);
        put(rj, "T_um", r.mean_T_um);
        Json counts;
        for (std::size_t c = 0; c < 3; ++c)
            counts[std::string(to_string(static_cast<RoughnessClass>(c)))] = r.class_counts[c];
        rj["class_counts"] = counts;
        regions.push_back(rj);
    }
    out["regions"] = regions;
    out["warnings"] = m.warnings;
    return out;
}

std::vector<MapLayer> map_float_layers(const image::RoughnessMap& m) {
    const std::vector<MapLayer> all{
        {"sigma_over_T_gaussian", &m.sigma_over_T_gaussian},
        {"sigma_over_T_gaussian_stderr", &m.sigma_over_T_gaussian_stderr},
        {"sigma_over_T_exponential", &m.sigma_over_T_exponential},
        {"sigma_over_T_exponential_stderr", &m.sigma_over_T_exponential_stderr},
        {"E1_over_E2", &m.E1_over_E2},
        {"T_um", &m.T_um},
        {"T_um_stderr", &m.T_um_stderr},
    };
    std::vector<MapLayer> made;  // (the layers the map made)
    for (const MapLayer& layer : all)
        if (!layer.values->empty()) made.push_back(layer);
    return made;
}

std::vector<MapClassLayer> map_class_layers(const image::RoughnessMap& m) {
    std::vector<MapClassLayer> layers{{"roughness_class", &m.roughness_class}};
    if (!m.roughness_class_g.empty()) layers.push_back({"roughness_class_g", &m.roughness_class_g});
    return layers;
}

Json to_json(const image::RegionStatistics& s) {
    Json out;
    out["pixels_in_region"] = s.pixels_in_region;
    out["pixels_used"] = s.pixels_used;
    out["pixels_saturated"] = s.pixels_saturated;
    out["pixels_clipped_low"] = s.pixels_clipped_low;
    Json channels = Json::array();
    for (const auto& c : s.channels) channels.push_back(channel_json(c));
    out["channels"] = channels;
    out["average"] = channel_json(s.average);
    out["warnings"] = s.warnings;
    return out;
}

namespace {

// The budget (measure/budget.hpp): for each headline quantity Q, Q_uncertainty (k = 1) and
// Q_interval95 beside Q and Q_stderr (the statistical part), and the budget's lines.
// The exact series' quantities (*_series_*) are under "exact_series", not beside the headline.
bool headline(std::string_view quantity) { return quantity.find("_series") == std::string::npos; }

void put_budget(Json& out, const std::optional<image::UncertaintyBudget>& b) {
    for (const char* q : image::kBudgetQuantities) {
        if (!headline(q)) continue;
        out[std::string(q) + "_uncertainty"] = Json();
        out[std::string(q) + "_interval95"] = Json();
    }
    Json budget = Json::object();
    if (b) {
        for (const image::QuantityBudget& q : b->quantities) {
            const OutputUncertainty& u = q.result;
            budget[q.quantity] = budget_json(u.budget);
            if (!headline(q.quantity)) continue;
            out[q.quantity + "_uncertainty"] = number(u.uncertainty);
            out[q.quantity + "_interval95"] =
                Json::array({number(u.interval95_low), number(u.interval95_high)});
        }
    }
    out["uncertainty_method"] = b ? Json(std::string(to_string(b->method))) : Json();
    out["uncertainty_method_reason"] =
        b && !b->method_reason.empty() ? Json(b->method_reason) : Json();
    out["uncertainty_trials"] =
        b && !b->quantities.empty() && b->method == PropagationMethod::MonteCarlo
            ? Json(b->quantities.front().result.trials)
            : Json();
    out["uncertainty_budget"] = b ? budget : Json();
    out["uncertainty_assumed"] = b ? Json(b->assumed) : Json();
}

// The exact series (measure/exact_series.hpp): per correlation σ, T, σ/T with its standard
// uncertainty and 95 % interval, the closed form's σ/T and its relative deviation, g at each
// capture used.
Json exact_series_json(const image::ExactSeriesEstimate& e) {
    Json out;
    out["method"] = std::string(image::to_string(e.method));
    out["method_description"] = image::describe(e);
    Json captures = Json::array();
    for (const std::size_t k : e.captures) captures.push_back(k + 1);
    out["captures"] = captures;  // 1-based, as the warnings name them
    out["uncertainty_covers"] = e.covers;
    for (const image::ExactSeriesCorrelation& c : e.correlations) {
        Json cj;
        put(cj, "sigma_um", c.sigma_um);
        put(cj, "T_um", c.T_um);
        put(cj, "sigma_over_T", c.sigma_over_T);
        cj["sigma_over_T_interval95"] =
            c.interval95_low && c.interval95_high
                ? Json::array({number(*c.interval95_low), number(*c.interval95_high)})
                : Json();
        if (e.method == image::ExactSeriesMethod::Fit) {
            const auto pair = [](const std::optional<std::array<double, 2>>& v) {
                return v ? Json::array({number((*v)[0]), number((*v)[1])}) : Json();
            };
            cj["sigma_um_interval95"] = pair(c.sigma_um_interval95);
            cj["T_um_interval95"] = pair(c.T_um_interval95);
            cj["sigma_determined"] = c.sigma_determined;
            cj["T_determined"] = c.T_determined;
        }
        cj["closed_form_sigma_over_T"] = number(c.closed_form_sigma_over_T);
        cj["closed_form_deviation_rel"] = number(c.closed_form_deviation_rel);
        cj["closed_form_off"] = c.closed_form_off;
        cj["g"] = numbers(c.g);
        cj["fit_status"] = c.fit_status.empty() ? Json() : Json(c.fit_status);
        cj["failure"] = c.failure.empty() ? Json() : Json(c.failure);
        out[std::string(to_string(c.correlation))] = cj;
    }
    out["warnings"] = e.warnings;
    return out;
}

// The photometric-stereo regions (measure/photometric_regions.hpp): name, pixels, with_slope,
// sigma_over_T (the median, ± _stderr), mean_sigma_over_T, roughness_class, class_counts,
// median_albedo, median_residual.
Json photometric_regions_json(const std::vector<image::PhotometricRegionStatistics>& regions) {
    Json out = Json::array();
    for (const image::PhotometricRegionStatistics& r : regions) {
        Json j;
        j["name"] = r.name;
        j["pixels"] = r.pixels;
        j["with_slope"] = r.with_slope;
        put(j, "sigma_over_T", r.sigma_over_T);
        j["mean_sigma_over_T"] = number(r.mean_sigma_over_T);
        j["roughness_class"] =
            r.roughness_class ? Json(std::string(to_string(*r.roughness_class))) : Json();
        j["class_counts"] = {{"slightly_rough", r.class_counts[0]},
                             {"moderately_rough", r.class_counts[1]},
                             {"very_rough", r.class_counts[2]}};
        j["median_albedo"] = number(r.median_albedo);
        j["median_residual"] = number(r.median_residual);
        out.push_back(j);
    }
    return out;
}

}  // namespace

Json to_json(const image::MeasureResult& r, const image::MeasureRequest& request) {
    Json out;
    out["format"] = "roughscope-measurement";
    out["version"] = 1;
    out["capture_file"] = text_or_null(request.source);
    put(out, "E1_over_E2", r.E1_over_E2);
    // σ/T of both correlations; σ and T where the captures give them.
    // More than two diffuse captures: σ/T from the least-squares fit of all of them (when it
    // converged with a covariance), else from the first two (Eq. 17 / 19 or the solver).
    const auto slope = [&](const std::optional<RoughnessEstimate>& pair,
                           const FitResult* fit) -> std::optional<Estimate> {
        if (fit && fit->status == SolverStatus::Converged && fit->covariance_available &&
            !fit->parameters.empty() && fit->parameters[0].name == "sigma_over_T")
            return Estimate{fit->parameters[0].value, fit->parameters[0].std_error};
        return pair ? pair->sigma_over_T : std::nullopt;
    };
    if (r.cylinder) {
        // A cylinder: σ/T fitted on its profile (§5.2).
        const Json profile = to_json(*r.cylinder);
        for (const Correlation c : kCorrelations) {
            const std::string key = correlation_key("sigma_over_T", c);
            out[key] = profile[key];
            out[key + "_stderr"] = profile[key + "_stderr"];
        }
        out["sigma_over_T_source"] = "cylinder_profile";
    } else {
        put(out, "sigma_over_T_gaussian",
            slope(r.slope_gaussian, r.fit ? &r.fit->gaussian : nullptr));
        put(out, "sigma_over_T_exponential",
            slope(r.slope_exponential, r.fit ? &r.fit->exponential : nullptr));
        out["sigma_over_T_source"] = r.fit                                     ? "fit"
                                     : r.slope_gaussian || r.slope_exponential ? "pair"
                                                                               : Json();
    }
    std::optional<Estimate> sigma;
    if (request.sigma_um)
        sigma = Estimate{*request.sigma_um, request.sigma_um_stderr};
    else if (r.sigma && r.sigma->sigma_um)
        sigma = r.sigma->sigma_um;
    put(out, "sigma_um", sigma);
    std::optional<Estimate> T;
    // The form T comes from: the regime of T given σ (given in the capture file, or chosen by
    // the sample's g), or σ/(σ/T) of Eq. 17 (very rough) when T given σ has no solution.
    Json T_regime, T_regime_source;
    if (r.correlation_length && r.correlation_length->T_um) {
        T = r.correlation_length->T_um;
        if (r.correlation_length_regime) {
            T_regime = std::string(to_string(*r.correlation_length_regime));
            T_regime_source = r.correlation_length_regime_given ? "capture_file" : "g";
        }
    } else if (r.slope_gaussian && r.slope_gaussian->T_um) {
        T = r.slope_gaussian->T_um;
        T_regime = std::string(to_string(Regime::VeryRough));
        T_regime_source = "sigma_over_T";
    }
    put(out, "T_um", T);
    out["T_um_regime"] = T_regime;
    out["T_um_regime_source"] = T_regime_source;
    // Derived quantities (§3.5) and the class: from the Gaussian σ/T when there is one, else from
    // T given σ, else from the specular σ.
    const RoughnessEstimate* derived = r.slope_gaussian       ? &*r.slope_gaussian
                                       : r.correlation_length ? &*r.correlation_length
                                       : r.sigma              ? &*r.sigma
                                                              : nullptr;
    put(out, "rms_slope", derived ? derived->rms_slope : std::nullopt);
    if (!derived && r.cylinder) {
        out["theta_K_deg"] = degrees_or_null(r.cylinder->theta_K_rad);
        out["theta_K_deg_stderr"] = Json();
    } else {
        put(out, "theta_K_deg", derived ? degrees_of(derived->theta_K_rad) : std::nullopt);
    }
    put(out, "xi_K", derived ? derived->xi_K : std::nullopt);
    // The class: from g when σ is known (the specular estimate or T given σ), else assumed.
    const RoughnessEstimate* classed = r.correlation_length ? &*r.correlation_length
                                       : r.sigma            ? &*r.sigma
                                                            : derived;
    out["roughness_class"] =
        classed ? Json(std::string(to_string(classed->roughness_class))) : Json();
    out["roughness_class_assumed"] = classed ? Json(classed->roughness_class_assumed) : Json();
    Json specular;
    if (!r.specular_sigma.empty()) {
        Json channels = Json::array();
        for (const auto& c : r.specular_sigma) {
            Json cj;
            cj["channel"] = c.channel;
            cj["wavelength_um"] = number(c.wavelength_um);
            put(cj, "sigma_um", c.estimate.sigma_um);
            cj["roughness_class"] = std::string(to_string(c.estimate.roughness_class));
            channels.push_back(cj);
        }
        specular["channels"] = channels;
        specular["channel_chi2"] = number(r.channel_sigma_chi2);
        specular["channel_dof"] = r.channel_sigma_dof;
    }
    out["specular"] = specular;
    out["slope_gaussian"] = optional_estimate(r.slope_gaussian);
    out["slope_exponential"] = optional_estimate(r.slope_exponential);
    out["correlation_length"] = optional_estimate(r.correlation_length);
    out["fit"] = r.fit ? to_json(*r.fit, false) : Json();
    Json region;
    if (request.roi) {
        region["description"] = image::describe(*request.roi);
        region["pixels"] = r.region_pixels;
    }
    out["region"] = region;
    Json object;
    object["shape"] = std::string(image::to_string(request.object.shape));
    if (request.object.shape == image::ObjectShape::NormalMap)
        object["normal_map"] = request.object.normal_map;
    out["object"] = object;
    out["cylinder"] = r.cylinder ? to_json(*r.cylinder) : Json();
    out["sphere"] = r.sphere ? to_json(*r.sphere) : Json();
    out["map"] = r.map ? to_json(*r.map) : Json();
    if (r.photometric_stereo) {
        Json ps = to_json(*r.photometric_stereo, r.photometric_lights);
        if (!r.photometric_regions.empty()) {
            ps["regions"] = photometric_regions_json(r.photometric_regions);
            Json comparisons = Json::array();
            for (const image::PhotometricRegionComparison& c : r.photometric_comparisons) {
                Json cj;
                cj["first"] = c.first;
                cj["second"] = c.second;
                cj["difference"] = number(c.difference);
                cj["difference_stderr"] = number(c.difference_stderr);
                cj["z"] = number(c.z);
                cj["p_value"] = number(c.p_value);
                cj["differ"] = c.differ;
                cj["same_class"] = c.same_class;
                comparisons.push_back(cj);
            }
            ps["comparisons"] = comparisons;
        }
        out["photometric_stereo"] = ps;
    }
    Json captures = Json::array();
    for (const auto& c : r.captures) captures.push_back(capture_json(c));
    out["captures"] = captures;
    put_budget(out, r.uncertainty);
    out["exact_series"] = r.exact_series ? exact_series_json(*r.exact_series) : Json();
    out["warnings"] = r.warnings;
    return out;
}

}  // namespace roughscope::serialize
