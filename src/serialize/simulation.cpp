// JSON, CSV and text forms of the simulation topic (serialize/simulation.hpp).
#include "roughscope/serialize/simulation.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::serialize {

namespace {

using simulation::ScatterOptions;
using simulation::ScatterResult;

// (diffuse − series)/stderr: how many standard errors the simulation is from the closed form.
Json deviation(const ScatterResult& r) {
    if (!(r.diffuse_stderr > 0.0)) return nullptr;
    return number((r.diffuse - r.series_diffuse) / r.diffuse_stderr);
}

}  // namespace

Json to_json(const ScatterResult& r) {
    Json out;
    out["theta_i_deg"] = degrees(r.geometry.theta_i_rad);
    out["theta_s_deg"] = degrees(r.geometry.theta_s_rad);
    out["phi_s_deg"] = degrees(r.geometry.phi_s_rad);
    out["g"] = number(r.g);
    out["T_vxy"] = number(r.T_vxy);
    out["F2"] = number(r.F2);
    out["diffuse"] = number(r.diffuse);
    out["diffuse_stderr"] = number(r.diffuse_stderr);
    out["coherent"] = number(r.coherent);
    out["coherent_stderr"] = number(r.coherent_stderr);
    out["series_diffuse"] = number(r.series_diffuse);
    out["series_coherent"] = number(r.series_coherent);
    out["diffuse_deviation"] = deviation(r);
    out["n"] = r.n;
    out["dx_um"] = number(r.dx_um);
    out["patch_um"] = number(static_cast<double>(r.n) * r.dx_um);
    out["area_um2"] = number(r.area_um2);
    out["realisations"] = r.realisations;
    out["layout"] = std::string(simulation::to_string(r.layout));
    out["lattice_index"] = r.lattice_index;
    return out;
}

Json to_json(const std::vector<ScatterResult>& results, const ScatterOptions& o) {
    Json options;
    options["correlation"] = std::string(to_string(o.correlation));
    options["sigma_um"] = number(o.sigma_um);
    options["T_um"] = number(o.T_um);
    options["wavelength_um"] = number(o.wavelength_um);
    options["factor"] = std::string(to_string(o.factor));
    options["n"] = o.n == 0 ? Json(nullptr) : Json(o.n);
    options["dx_um"] = o.dx_um == 0.0 ? Json(nullptr) : number(o.dx_um);
    options["patch_over_T"] = o.patch_over_T == 0.0 ? Json(nullptr) : number(o.patch_over_T);
    options["realisations"] = o.realisations;
    options["seed"] = o.seed;
    options["layout"] = std::string(simulation::to_string(o.layout));
    Json out;
    out["options"] = std::move(options);
    Json rows = Json::array();
    for (const ScatterResult& r : results) rows.push_back(to_json(r));
    out["results"] = std::move(rows);
    return out;
}

std::string scatter_csv(const std::vector<ScatterResult>& results) {
    std::string out;
    const Json header_source = to_json(ScatterResult{});
    bool first = true;
    for (const auto& item : header_source.items()) {
        if (!first) out += ',';
        out += item.key();
        first = false;
    }
    out += '\n';
    for (const ScatterResult& r : results) {
        const Json row = to_json(r);
        first = true;
        for (const auto& item : row.items()) {
            if (!first) out += ',';
            first = false;
            const Json& v = item.value();
            if (v.is_null()) continue;  // an empty cell: unknown
            if (v.is_string()) {
                out += v.get<std::string>();
            } else {
                out += v.dump();
            }
        }
        out += '\n';
    }
    return out;
}

std::string to_text(const std::vector<ScatterResult>& results, const ScatterOptions& o) {
    std::string out = concat("Monte Carlo Kirchhoff scattering: ", to_string(o.correlation),
                             " correlation, sigma = ", format_message(o.sigma_um),
                             " um, T = ", format_message(o.T_um),
                             " um, lambda = ", format_message(o.wavelength_um), " um, factor ",
                             to_string(o.factor), ", seed ", std::to_string(o.seed), "\n");
    char line[512];
    std::snprintf(line, sizeof line, "%8s %8s %8s %10s %8s %13s %11s %13s %7s %13s %11s %5s %6s\n",
                  "theta_i", "theta_s", "phi_s", "g", "T*v_xy", "diffuse", "stderr", "series",
                  "dev", "coherent", "stderr", "n", "R");
    out += line;
    for (const ScatterResult& r : results) {
        const double dev =
            r.diffuse_stderr > 0.0 ? (r.diffuse - r.series_diffuse) / r.diffuse_stderr : 0.0;
        std::snprintf(line, sizeof line,
                      "%8.3f %8.3f %8.3f %10.4g %8.4g %13.6g %11.3g %13.6g %7.2f %13.6g %11.3g "
                      "%5zu %6zu\n",
                      rad_to_deg(r.geometry.theta_i_rad), rad_to_deg(r.geometry.theta_s_rad),
                      rad_to_deg(r.geometry.phi_s_rad), r.g, r.T_vxy, r.diffuse, r.diffuse_stderr,
                      r.series_diffuse, dev, r.coherent, r.coherent_stderr, r.n, r.realisations);
        out += line;
    }
    out +=
        "diffuse, coherent: Monte Carlo estimates (stderr: their standard errors); series: the "
        "exact series (Eq. 2 or the exponential series) with the simulated patch's area; dev: "
        "(diffuse - series)/stderr\n";
    return out;
}

}  // namespace roughscope::serialize
