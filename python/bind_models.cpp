// Python bindings of the retro-scattering closed forms (Eq. 7–11), validity (§3.1, §3.5) and the
// comparison models of §5 (Lambert, Oren–Nayar, Lafortune). Array arguments broadcast as
// array_loops.hpp describes.
#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "array_loops.hpp"
#include "bindings.hpp"
#include "roughscope/roughscope.hpp"

namespace py = pybind11;

namespace roughscope::python {
namespace {

// =============================================================================================
// Lafortune lobes from Python
// =============================================================================================

std::vector<LafortuneLobe> lobes_from_python(py::handle lobes) {
    std::vector<LafortuneLobe> result;
    // One dict is one lobe; the list made of it is held here (a handle alone would dangle).
    py::object held = py::reinterpret_borrow<py::object>(lobes);
    if (py::isinstance<py::dict>(lobes)) held = py::list(py::make_tuple(lobes));
    lobes = held;
    bool sequence_of_dicts = py::isinstance<py::sequence>(lobes) && !py::isinstance<py::str>(lobes);
    if (sequence_of_dicts) {
        auto seq = py::reinterpret_borrow<py::sequence>(lobes);
        for (py::handle item : seq)
            if (!py::isinstance<py::dict>(item)) sequence_of_dicts = false;
        if (sequence_of_dicts && py::len(seq) > 0) {
            std::size_t index = 0;
            for (py::handle item : seq) {
                auto d = py::reinterpret_borrow<py::dict>(item);
                LafortuneLobe lobe;
                for (auto kv : d) {
                    const std::string key = py::str(kv.first);
                    // TypeError for a non-real value, InvalidArgument (ValueError) for an array.
                    const std::string where = "lobes[" + std::to_string(index) + "]['" + key + "']";
                    const double v = real_scalar(where.c_str(), kv.second);
                    if (key == "Cx")
                        lobe.Cx = v;
                    else if (key == "Cy")
                        lobe.Cy = v;
                    else if (key == "Cz")
                        lobe.Cz = v;
                    else if (key == "n")
                        lobe.n = v;
                    else if (key == "albedo" || key == "rho")
                        lobe.albedo = v;
                    else
                        throw InvalidArgument("lobes: unknown key '" + key +
                                              "' (expected Cx, Cy, Cz, n, albedo)");
                }
                result.push_back(lobe);
                ++index;
            }
            return result;
        }
    }
    DoubleArray a = to_double_array("lobes", lobes);
    if (a.ndim() == 1 && a.shape(0) == 5) a = to_double_array("lobes", a.reshape({1, 5}));
    if (a.ndim() != 2 || a.shape(1) != 5)
        throw InvalidArgument(
            "lobes must be a list of dicts (Cx, Cy, Cz, n, albedo) or an array "
            "of shape (N, 5) with columns Cx, Cy, Cz, n, albedo; got shape " +
            shape_string({a.shape(), a.shape() + a.ndim()}));
    for (ssize_t k = 0; k < a.shape(0); ++k) {
        const double* row = a.data() + 5 * k;
        result.push_back(LafortuneLobe{row[0], row[1], row[2], row[3], row[4]});
    }
    return result;
}

}  // namespace

void bind_retro_and_validity(py::module_& m) {
    using py::arg;

    // ---- Retro-scattering closed forms (Eq. 7–11) -----------------------------------------
    auto retro_vr = [&m](const char* name, double (*fn)(double, double), const char* doc) {
        m.def(
            name,
            [fn](py::handle theta_deg, py::handle sigma_over_T) {
                return map_double<2>({"theta_deg", "sigma_over_T"}, {theta_deg, sigma_over_T},
                                     [fn](double t, double r) { return fn(deg_to_rad(t), r); });
            },
            py::arg("theta_deg"), py::arg("sigma_over_T"), doc);
    };
    retro_vr("retro_beckmann_gaussian_very_rough", &retro_beckmann_gaussian_very_rough,
             "Eq. 7 (original B–K, Gaussian correlation, very rough, retro θi = θs = θ, φs = "
             "180): exp(−T² tan²θ/(4σ²)) / cos⁶θ. theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_beckmann_exponential_very_rough", &retro_beckmann_exponential_very_rough,
             "Eq. 8 (original B–K, exponential correlation): 1 / (cos⁶θ [1 + (T/σ)² "
             "tan²θ]^{3/2}). theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_vh_gaussian_very_rough", &retro_vh_gaussian_very_rough,
             "Eq. 9 (V–H modified B–K, Gaussian correlation): exp(−T² tan²θ/(4σ²)) / cos θ. "
             "theta_deg in [0, 90), sigma_over_T > 0.");
    retro_vr("retro_vh_exponential_very_rough", &retro_vh_exponential_very_rough,
             "Eq. 10 (V–H modified B–K, exponential correlation): 1 / (cos θ [1 + (T/σ)² "
             "tan²θ]^{3/2}). theta_deg in [0, 90), sigma_over_T > 0.");
    m.def(
        "retro_vh_gaussian_slightly_rough",
        [](py::handle theta_deg, py::handle sigma_um, py::handle T_um, py::handle wavelength_um) {
            return map_double<4>({"theta_deg", "sigma_um", "T_um", "wavelength_um"},
                                 {theta_deg, sigma_um, T_um, wavelength_um},
                                 [](double t, double s, double T, double wl) {
                                     return retro_vh_gaussian_slightly_rough(deg_to_rad(t), s, T,
                                                                             wl);
                                 });
        },
        arg("theta_deg"), arg("sigma_um"), arg("T_um"), arg("wavelength_um") = 0.555,
        R"doc(Eq. 11 (V–H, Gaussian correlation, slightly rough, retro):
cos³θ exp(−k² ([T sin θ]² + [2σ cos θ]²)), k = 2π/λ. Lengths in µm.)doc");

    // ---- Validity (§3.1, §3.5) ------------------------------------------------------------
    m.def(
        "roughness_class",
        [](py::handle g) {
            auto operands = broadcast<1>({"g"}, {g});
            auto& ops = operands.first;  // not a structured binding (the lambdas below name it)
            auto& b = operands.second;
            py::array_t<std::uint8_t> codes(b.shape);
            std::uint8_t* oc = codes.mutable_data();
            for_each_element(b, true, [&](ssize_t i) {
                const double gg = ops[0].data[i * ops[0].step];
                check::non_negative("g", gg);
                oc[i] = code_of(kRoughnessClasses, roughness_class(gg));
            });
            return names_from_codes(b, codes, enum_names(kRoughnessClasses));
        },
        arg("g"),
        R"doc(Roughness class by g (§3.1): 'slightly_rough' for g < 0.1, 'very_rough' for g > 10,
'moderately_rough' otherwise. A str for scalar g, else a NumPy str array.)doc");

    m.def(
        "rms_slope",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return rms_slope(r);
            });
        },
        arg("sigma_over_T"), "RMS slope m = σ√2/T (§4; Gaussian correlation). sigma_over_T >= 0.");
    m.def(
        "caron_theta_K_deg",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return rad_to_deg(caron_theta_K_rad(r));
            });
        },
        arg("sigma_over_T"),
        "Caron's angle of RMS slope θK = 90° − atan(σ√2/T) in degrees (§3.5): incidence "
        "angles above it are outside the model's validity. sigma_over_T >= 0.");
    m.def(
        "caron_xi_K",
        [](py::handle sigma_over_T) {
            return map_double<1>({"sigma_over_T"}, {sigma_over_T}, [](double r) {
                check::non_negative("sigma_over_T", r);
                return caron_xi_K(r);
            });
        },
        arg("sigma_over_T"),
        "Caron's energy conservation rate at normal incidence, g >> 1: ξK = 1 − exp(−T²/(4σ²)) "
        "(§3.5). sigma_over_T >= 0.");
}

void bind_reflectance_models(py::module_& m) {
    using py::arg;

    // ---- Comparison models (§5) -----------------------------------------------------------
    m.def(
        "lambert_brightness",
        [](py::handle theta_i_deg) {
            return map_double<1>({"theta_i_deg"}, {theta_i_deg},
                                 [](double t) { return lambert_brightness(deg_to_rad(t)); });
        },
        arg("theta_i_deg"), "Lambert's cosine law: cos θi (θi in degrees, [0, 90)).");

    auto oren_nayar_like = [&m](const char* name, auto fn, const char* doc) {
        m.def(
            name,
            [fn](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg,
                 py::handle sigma_rad, py::handle albedo) {
                return map_double<5>(
                    {"theta_i_deg", "theta_s_deg", "phi_s_deg", "sigma_rad", "albedo"},
                    {theta_i_deg, theta_s_deg, phi_s_deg, sigma_rad, albedo},
                    [fn](double ti, double ts, double ps, double s, double a) {
                        return fn(geometry_deg(ti, ts, ps), OrenNayarParams{s, a});
                    });
            },
            py::arg("theta_i_deg"), py::arg("theta_s_deg"), py::arg("phi_s_deg"),
            py::arg("sigma_rad"), py::arg("albedo") = 1.0, doc);
    };
    oren_nayar_like(
        "oren_nayar_radiance",
        [](const Geometry& g, const OrenNayarParams& p) { return oren_nayar_radiance(g, p); },
        "Full Oren–Nayar model (1994) with the inter-reflection term, radiance for unit "
        "irradiance. sigma_rad: standard deviation of the facet slope angle in radians (>= 0; "
        "not the height σ); albedo in [0, 1]. σ = 0 gives (ρ/π) cos θi. Angles in degrees.");
    oren_nayar_like(
        "oren_nayar_qualitative_radiance",
        [](const Geometry& g, const OrenNayarParams& p) {
            return oren_nayar_qualitative_radiance(g, p);
        },
        "Qualitative Oren–Nayar model: (ρ/π) cos θi [A + B max(0, cos(φr − φi)) "
        "sin α tan β]. sigma_rad in radians, albedo in [0, 1]; angles in degrees.");

    m.def(
        "lafortune_diffuse_brightness",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg, py::handle n) {
            return map_double<4>({"theta_i_deg", "theta_s_deg", "phi_s_deg", "n"},
                                 {theta_i_deg, theta_s_deg, phi_s_deg, n},
                                 [](double ti, double ts, double ps, double nn) {
                                     return lafortune_diffuse_brightness(geometry_deg(ti, ts, ps),
                                                                         nn);
                                 });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("n"),
        "Lafortune diffuse lobe (Cx = Cy = 0, Cz = 1) as the paper fits it to CUReT: brightness "
        "(cos θi cos θs)^n cos θi. Angles in degrees; n > 0.");

    m.def(
        "lafortune_brdf",
        [](py::handle theta_i_deg, py::handle theta_s_deg, py::handle phi_s_deg, py::handle lobes,
           py::handle rho_d_in) {
            const double rho_d = real_scalar("rho_d", rho_d_in);
            const std::vector<LafortuneLobe> lobe_list = lobes_from_python(lobes);
            return map_double<3>(
                {"theta_i_deg", "theta_s_deg", "phi_s_deg"}, {theta_i_deg, theta_s_deg, phi_s_deg},
                [&lobe_list, rho_d](double ti, double ts, double ps) {
                    return lafortune_brdf(geometry_deg(ti, ts, ps), lobe_list, rho_d);
                });
        },
        arg("theta_i_deg"), arg("theta_s_deg"), arg("phi_s_deg"), arg("lobes"), arg("rho_d") = 0.0,
        R"doc(Lafortune et al. (1997) BRDF: rho_d/π + Σ_lobes albedo [Cx Lx Vx + Cy Ly Vy + Cz Lz Vz]^n
(a lobe is 0 where its bracket is <= 0). lobes: a list of dicts with keys Cx, Cy, Cz, n, albedo
(missing keys: Cx = Cy = 0, Cz = 1, n = 1, albedo = 1), or an array of shape (N, 5) with those
columns. Angles in degrees; rho_d >= 0.)doc");
}

}  // namespace roughscope::python
