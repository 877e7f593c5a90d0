// Fuzz target: the CSV that `roughscope model --csv FILE` reads (cli/model.cpp): the library's
// CSV reader (io/csv.hpp) with the required columns theta_i, theta_s, phi_s (degrees) and the
// optional sigma_um, T_um, sigma_over_T, then each row's geometry in the paper's frame (§2) as the
// command builds it.
#include <sstream>
#include <string>

#include "fuzz_target.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/scattering/geometry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    roughscope::fuzz::expect_only_roughscope_errors([&] {
        std::istringstream in{std::string(roughscope::fuzz::as_text(data, size))};
        roughscope::io::CsvReader reader(in, "model.csv", {"theta_i", "theta_s", "phi_s"},
                                         {"sigma_um", "T_um", "sigma_over_T"});
        roughscope::io::CsvRow row;
        while (reader.next(row)) {
            for (const char* column : {"sigma_um", "T_um", "sigma_over_T"}) (void)row.find(column);
            (void)roughscope::make_geometry(roughscope::deg_to_rad(row.at("theta_i")),
                                            roughscope::deg_to_rad(row.at("theta_s")),
                                            roughscope::deg_to_rad(row.at("phi_s")));
        }
    });
    return 0;
}
