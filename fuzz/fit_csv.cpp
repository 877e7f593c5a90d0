// Fuzz target: the measurements CSV that `roughscope estimate fit --measurements FILE` reads
// (cli/estimate.cpp): the library's CSV reader (io/csv.hpp) with the required columns theta_i,
// phi_i, theta_s, phi_s (degrees, both azimuths in the sample frame), brightness and the optional
// weight, then each row as a fit Measurement (geometry_from_two_azimuths, §2).
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_target.hpp"
#include "roughscope/fit/fit.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/scattering/geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using roughscope::deg_to_rad;
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        std::istringstream in{std::string(roughscope::fuzz::as_text(data, size))};
        roughscope::io::CsvReader reader(in, "measurements.csv",
                                         {"theta_i", "phi_i", "theta_s", "phi_s", "brightness"},
                                         {"weight"});
        std::vector<roughscope::Measurement> measurements;
        roughscope::io::CsvRow row;
        while (reader.next(row)) {
            const double brightness = row.at("brightness");
            const double weight = row.find("weight").value_or(1.0);
            const roughscope::Geometry geometry = roughscope::geometry_from_two_azimuths(
                deg_to_rad(row.at("theta_i")), deg_to_rad(row.at("phi_i")),
                deg_to_rad(row.at("theta_s")), deg_to_rad(row.at("phi_s")));
            measurements.push_back({geometry, brightness, weight});
        }
    });
    return 0;
}
