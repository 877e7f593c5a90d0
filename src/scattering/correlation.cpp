// Messages of the correlation descriptor (correlation.hpp).
#include "roughscope/scattering/correlation.hpp"

#include <cmath>
#include <string>

#include "roughscope/core/numbers.hpp"

namespace roughscope {

std::string ratio_inverse_no_solution_detail(Correlation c, const NormalViewPair& p,
                                             double E1_over_E2) {
    const double radicand = ratio_inverse_radicand(c, p, E1_over_E2);
    switch (c) {
        case Correlation::Gaussian: {  // Eq. 17 needs κ = (E1/E2)/C on the side of 1 of a2 − a1
            const double kappa = std::exp(std::log(E1_over_E2) - std::log(p.C));
            return " (kappa = " +
                   (std::isfinite(kappa) ? format_message(kappa, 7) : std::string("above 1e308")) +
                   (p.a2 > p.a1 ? " must exceed 1)" : " must be below 1)");
        }
        case Correlation::Exponential:  // Eq. 19
            return std::isfinite(radicand)
                       ? " (the radicand of Eq. 19 is " + format_message(radicand, 7) + ")"
                       : std::string();
    }
    return {};
}

}  // namespace roughscope
