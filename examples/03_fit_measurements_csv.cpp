// Example 3 — least-squares fit of σ/T to a CSV of brightness measurements (paper §4: "if a
// larger number of measurements are available then least-square fitting techniques can be used").
//
//   1. writes measurements.csv (the layout of `roughscope estimate fit --measurements`: columns
//      theta_i, phi_i, theta_s, phi_s in degrees, brightness, optional weight) for a very rough
//      surface with a Gaussian correlation, σ/T = 0.6, an unknown camera gain and 1 % noise;
//   2. streams it back with the library's CSV reader (io/csv.hpp) into Measurements, converting
//      the two azimuths to the paper's frame;
//   3. fits both correlation functions with an unknown gain (the fit engine, Ceres) and compares
//      them by AIC: the Gaussian must win and σ/T must lie within 3 standard errors of the truth.
// Exits non-zero if a check fails, so the test suite runs it. Usage: example_03 [OUTPUT_DIR].
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "roughscope/core/numbers.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/roughscope.hpp"

namespace rs = roughscope;

int main(int argc, char** argv) {
    const std::filesystem::path dir = argc > 1 ? argv[1] : ".";
    const std::filesystem::path csv = dir / "example_03_measurements.csv";
    const double true_sigma_over_T = 0.6, gain = 250.0;

    // 1. Eight lighting directions, the camera at three polar angles and two azimuths (a
    //    CUReT-like frame: the light at azimuth phi_i = 0, the camera at phi_s).
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::string text = "# synthetic: Gaussian sigma/T = 0.6, gain 250, 1 % noise\n";
    text += "theta_i,phi_i,theta_s,phi_s,brightness\n";
    for (double theta_i : {5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0})
        for (double theta_s : {0.0, 30.0, 60.0})
            for (double phi_s : {90.0, 180.0}) {
                const rs::Geometry g = rs::geometry_from_two_azimuths(
                    rs::deg_to_rad(theta_i), 0.0, rs::deg_to_rad(theta_s), rs::deg_to_rad(phi_s));
                const double E =
                    gain *
                    rs::very_rough_brightness(g, true_sigma_over_T, rs::Correlation::Gaussian) *
                    (1.0 + noise(rng));
                text += rs::format_roundtrip(theta_i) + ",0," + rs::format_roundtrip(theta_s) +
                        "," + rs::format_roundtrip(phi_s) + "," + rs::format_roundtrip(E) + "\n";
            }
    rs::io::write_file_atomic(csv, text);

    // 2. Read it back row by row.
    rs::io::CsvReader reader(csv, {"theta_i", "phi_i", "theta_s", "phi_s", "brightness"},
                             {"weight"});
    std::vector<rs::Measurement> measurements;
    for (rs::io::CsvRow row; reader.next(row);) {
        rs::Measurement m;
        m.geometry = rs::geometry_from_two_azimuths(
            rs::deg_to_rad(row.at("theta_i")), rs::deg_to_rad(row.at("phi_i")),
            rs::deg_to_rad(row.at("theta_s")), rs::deg_to_rad(row.at("phi_s")));
        m.brightness = row.at("brightness");
        m.weight = row.find("weight").value_or(1.0);
        measurements.push_back(m);
    }
    std::printf("%zu measurements read from %s\n", measurements.size(), csv.string().c_str());

    // 3. Both correlations, gain profiled out.
    const rs::CorrelationComparison both = rs::compare_correlations(measurements);
    const rs::FitResult& fit = both.gaussian;
    std::printf("%s\n", fit.brief_report().c_str());
    const rs::FitParameter& s = fit.parameter("sigma_over_T");
    std::printf("sigma/T = %.4f +- %.4f (true %.2f); preferred: %s (delta AIC %.1f)\n", s.value,
                s.std_error, true_sigma_over_T, std::string(rs::to_string(both.preferred)).c_str(),
                both.delta_aic);
    if (fit.status != rs::SolverStatus::Converged || !fit.covariance_available) return 1;
    if (both.preferred != rs::Correlation::Gaussian) return 1;
    if (std::abs(s.value - true_sigma_over_T) > 3 * s.std_error) return 1;

    // One measurement cannot determine sigma/T and the gain: the status says so, with the reason,
    // and there is no estimate.
    const rs::FitResult one = rs::fit_roughness({measurements[0]});
    std::printf("one measurement: %s\n", one.message.c_str());
    if (one.status != rs::SolverStatus::NotIdentifiable || one.estimate.sigma_over_T) return 1;
    return 0;
}
