// `roughscope plan --sigma-over-T S`: the pair of light zeniths that minimises the predicted
// u(σ/T) of a measurement (measure/plan.hpp; docs/uncertainty.md "Planning a capture"). The JSON
// document is serialize/plan.hpp's (the same as roughscope.plan_capture's dict).
#include "roughscope/measure/plan.hpp"

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/estimation/propagation.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/plan.hpp"

namespace roughscope::cli {
namespace {

struct PlanCommand {
    image::PlanRequest request;
    double sigma_over_T_max = 0.0;
    double angle_deg = 0.0, exposure_rel = 0.0, black_level_rel = 0.0;
    std::size_t range_points = 5, top = 10;
    bool json_output = false;
    CLI::Option *o_max{}, *o_angle{}, *o_exposure{}, *o_black{};
};

void run_plan(PlanCommand& c) {
    image::PlanRequest& r = c.request;
    if (given(c.o_max)) r.sigma_over_T_max = c.sigma_over_T_max;
    if (given(c.o_angle)) r.tolerances.angle_deg = c.angle_deg;
    if (given(c.o_exposure)) r.tolerances.exposure_rel = c.exposure_rel;
    if (given(c.o_black)) r.black_level_rel = c.black_level_rel;
    r.range_points = c.range_points;
    r.top = c.top;
    const image::CapturePlan plan = image::plan_capture(r);
    write_output(std::nullopt, c.json_output
                                   ? serialize::dump(serialize::versioned(serialize::to_json(plan)))
                                   : serialize::plan_text(plan));
}

}  // namespace

void register_plan(CLI::App& app) {
    auto args = std::make_shared<PlanCommand>();
    PlanCommand& c = *args;
    image::PlanRequest& r = c.request;
    CLI::App* cmd = app.add_subcommand(
        "plan",
        "Plan a capture: the pair of light zeniths (camera on the normal) with the smallest "
        "predicted u(sigma/T) at the setup's tolerances (docs/uncertainty.md)");
    add_positive_option(*cmd, "--sigma-over-T", r.sigma_over_T,
                        "The expected sigma/T (the lower end of a range with --sigma-over-T-max)")
        ->required();
    c.o_max = add_positive_option(*cmd, "--sigma-over-T-max", c.sigma_over_T_max,
                                  "The upper end of the expected sigma/T: the worst relative "
                                  "uncertainty over the range is minimised");
    cmd->add_option("--range-points", c.range_points,
                    "Points of the sigma/T range evaluated (2-50; default 5)")
        ->transform(integer_validator(2, 50));
    add_enum_option(*cmd, "--correlation", r.correlation, parse_correlation,
                    "gaussian (Eq. 17, default) or exponential (Eq. 19)");
    add_factor_option(*cmd, r.factor);
    c.o_angle = add_non_negative_option(
        *cmd, "--angle-deg", c.angle_deg,
        "Standard uncertainty of each light's zenith and of the camera's tilt (deg; default 0.5)",
        "deg");
    c.o_exposure = add_non_negative_option(
        *cmd, "--exposure-rel", c.exposure_rel,
        "Standard uncertainty of each capture's exposure, relative (default 0.01)");
    c.o_black = add_non_negative_option(
        *cmd, "--black-level-rel", c.black_level_rel,
        "Standard uncertainty of the black level, a fraction of full scale (default 0.002)");
    add_non_negative_option(*cmd, "--noise-rel", r.noise_rel,
                            "Relative standard uncertainty of a region mean at --fill of full "
                            "scale (pixel noise; default 0.002)");
    add_positive_option(*cmd, "--fill", r.fill,
                        "Fraction of full scale the sample reaches (default 0.8)");
    add_enum_option(*cmd, "--exposure", r.exposure, image::parse_plan_exposure,
                    "per-capture (each capture exposed to --fill, default) or common (one "
                    "exposure, the brighter capture at --fill)");
    add_angle_option(*cmd, "--theta-min", r.theta_min_deg,
                     "Smallest light zenith of the grid (deg; default 5)");
    add_angle_option(*cmd, "--theta-max", r.theta_max_deg,
                     "Largest light zenith of the grid (deg; default 75)");
    add_positive_option(*cmd, "--theta-step", r.theta_step_deg, "Step of the grid (deg; default 1)",
                        "deg");
    add_non_negative_option(*cmd, "--min-difference", r.min_difference_deg,
                            "Smallest theta2 - theta1 (deg; default 5)", "deg");
    cmd->add_option("--top", c.top, "Pairs listed (1-1000; default 10)")
        ->transform(integer_validator(1, 1000));
    add_enum_option(*cmd, "--method", r.propagation.method, parse_propagation_method,
                    "Propagation of the recommended and the 30/45 pair: auto (default), "
                    "first_order or monte_carlo (the search is first order)");
    cmd->add_flag("--json", c.json_output, "Print JSON (keys in docs/uncertainty.md)");
    cmd->callback([args]() { run_plan(*args); });
}

}  // namespace roughscope::cli
