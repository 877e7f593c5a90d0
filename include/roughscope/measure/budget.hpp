// The uncertainty budget of a measurement (docs/uncertainty.md): the setup's declared standard
// uncertainties (the capture file's "uncertainty"), propagated with the pixel noise to every
// headline quantity by estimation/propagation.hpp.
#pragma once

#include <cstddef>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "roughscope/estimation/propagation.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {

// Standard uncertainties (k = 1) of a setup. Unset: the default of a hand-set bench below, listed
// in the result as assumed.
struct SetupTolerances {
    std::optional<double> angle_deg;       // every light and view zenith and azimuth, degrees
    std::optional<double> exposure_rel;    // each capture's exposure scale, relative
    std::optional<double> black_level_dn;  // the black level: one error for every photograph, DN
    std::optional<double> response_gamma;  // γ, or the sRGB curve's exponent (2.4)
    std::optional<double> wavelength_um;   // the effective wavelength, µm
    std::optional<double> flat_field_rel;  // the flat field between two regions, relative
    // The smallest g = σ² v_z² the sample is taken to have at either capture when σ is unknown:
    // the very-rough σ/T (Eq. 17) carries the model error of that limit over g ≥ this.
    double very_rough_min_g = 10.0;  // kVeryRoughMinG (scattering/validity.hpp)
};

// A capture's own standard uncertainties, over the setup's.
struct CaptureTolerances {
    std::optional<double> theta_i_deg;
    std::optional<double> theta_s_deg;
    std::optional<double> phi_s_deg;
    std::optional<double> exposure_rel;
};

// The defaults of a hand-set bench (docs/uncertainty.md "Defaults"): angles read off a protractor
// to about ½°, a shutter repeatable to 1 %, a black level known to 0.2 % of full scale (RAW: 0.05
// %, the metadata's), a response exponent to 0.05, the effective wavelength of a colour channel
// or of the RGB average to 20 nm, a flat field to 1 % (0.2 % when one is given).
inline constexpr double kDefaultAngleUncertaintyDeg = 0.5;
inline constexpr double kDefaultExposureUncertaintyRel = 0.01;
inline constexpr double kDefaultBlackLevelFraction = 0.002;
inline constexpr double kDefaultRawBlackLevelFraction = 0.0005;
inline constexpr double kDefaultResponseGammaUncertainty = 0.05;
inline constexpr double kDefaultWavelengthUncertaintyUm = 0.02;
inline constexpr double kDefaultFlatFieldUncertaintyRel = 0.01;
inline constexpr double kDefaultFlatFieldGivenUncertaintyRel = 0.002;

// The headline quantities, in the order of UncertaintyBudget::quantities. The *_series ones are
// the exact series' (measure/exact_series.hpp): with σ known, T given σ from the first diffuse
// pair in Regime::Series for that correlation, and σ/T = σ/T_series.
inline constexpr const char* kBudgetQuantities[] = {"E1_over_E2",
                                                    "sigma_over_T_gaussian",
                                                    "sigma_over_T_exponential",
                                                    "sigma_um",
                                                    "T_um",
                                                    "sigma_over_T_series_gaussian",
                                                    "sigma_over_T_series_exponential",
                                                    "T_um_series_gaussian",
                                                    "T_um_series_exponential"};
inline constexpr std::size_t kBudgetQuantityCount = std::size(kBudgetQuantities);

struct QuantityBudget {
    std::string quantity;  // one of kBudgetQuantities
    OutputUncertainty result;
};

struct UncertaintyBudget {
    PropagationMethod method = PropagationMethod::FirstOrder;  // as used
    std::string method_reason;  // why Monte Carlo was used, else empty
    std::vector<QuantityBudget>
        quantities;  // those the measurement has, in kBudgetQuantities order
    // The tolerances taken from the defaults ("angle_deg = 0.5"): the budget rests on them.
    std::vector<std::string> assumed;
    std::vector<std::string> warnings;
};

// A geometry whose angles moved by an error (the budget's and the plan's model): a negative
// zenith is the same direction at |θ| on the other side (φs + π); a zenith at or past 90° has no
// value.
std::optional<Geometry> signed_geometry(double theta_i_rad, double theta_s_rad, double phi_s_rad);

}  // namespace roughscope::image
