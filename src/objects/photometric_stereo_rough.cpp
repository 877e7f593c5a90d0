// Rough-surface photometric stereo, one pixel (photometric_stereo_rough.hpp).
#include "photometric_stereo_rough.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Dense>

#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kScan = 16;  // log-spaced σ/T values of the starting scan
constexpr int kMaxIterations = 60;
constexpr double kStep = 1e-6;  // central-difference step of the parameters
constexpr double kTinyVariance = 1e-300;

// The pixel's model at parameters x = (u, v, ln σ/T): n = normalise(n0 + u t1 + v t2).
class Model {
  public:
    explicit Model(const RoughPixelProblem& p) : p_(p) {
        const Eigen::Vector3d& n0 = p.start_normal;
        const Eigen::Vector3d a =
            std::abs(n0.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
        t1_ = n0.cross(a).normalized();
        t2_ = n0.cross(t1_);
    }

    Eigen::Vector3d normal(const Eigen::Vector3d& x) const {
        return (p_.start_normal + x(0) * t1_ + x(1) * t2_).normalized();
    }

    // B_j for the lights of `set` (0 for a light at or below the local horizon).
    void brightness(const Eigen::Vector3d& x, std::uint32_t set, std::array<double, 32>& b) const {
        const Eigen::Vector3d n = normal(x);
        const double s = std::exp(x(2));
        const auto& lights = *p_.lights;
        for (std::size_t j = 0; j < lights.size(); ++j) {
            b[j] = 0.0;
            if (!(set & (1U << j))) continue;
            const std::optional<Geometry> g =
                geometry_from_vectors(n, lights[j], Eigen::Vector3d::UnitZ(), 1e-9);
            if (g && g->theta_i_rad < 1.5 && g->theta_s_rad < 1.5)
                b[j] = very_rough_brightness(*g, s, p_.correlation);
        }
    }

    // Residuals r_j = I_j − ρ B_j with ρ projected out (0 for lights outside `set`); ρ returned.
    double residuals(const Eigen::Vector3d& x, std::uint32_t set, Eigen::VectorXd& r) const {
        std::array<double, 32> b{};
        brightness(x, set, b);
        const auto& lights = *p_.lights;
        double ib = 0.0, bb = 0.0;
        for (std::size_t j = 0; j < lights.size(); ++j)
            if (set & (1U << j)) {
                ib += p_.value[j] * b[j];
                bb += b[j] * b[j];
            }
        const double rho = bb > 0.0 ? ib / bb : 0.0;
        r.setZero(static_cast<Eigen::Index>(lights.size()));
        for (std::size_t j = 0; j < lights.size(); ++j)
            if (set & (1U << j)) r(static_cast<Eigen::Index>(j)) = p_.value[j] - rho * b[j];
        return rho;
    }

    double sse(const Eigen::Vector3d& x, std::uint32_t set) const {
        Eigen::VectorXd r;
        residuals(x, set, r);
        return r.squaredNorm();
    }

  private:
    const RoughPixelProblem& p_;
    Eigen::Vector3d t1_, t2_;
};

// The Jacobian of the residuals (ρ projected out) with respect to x, by central differences.
Eigen::MatrixXd jacobian_at(const Model& m, const Eigen::Vector3d& x, std::uint32_t set,
                            Eigen::Index rows) {
    Eigen::MatrixXd J(rows, 3);
    Eigen::VectorXd rp, rm;
    for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d xp = x, xm = x;
        xp(a) += kStep;
        xm(a) -= kStep;
        m.residuals(xp, set, rp);
        m.residuals(xm, set, rm);
        J.col(a) = (rp - rm) / (2 * kStep);
    }
    return J;
}

// Levenberg–Marquardt on x from `x`, ln σ/T kept within [ln lo, ln hi].
Eigen::Vector3d minimise(const Model& m, Eigen::Vector3d x, std::uint32_t set, double lo,
                         double hi) {
    double lambda = 1e-3;
    Eigen::VectorXd r;
    double cost = m.sse(x, set);
    for (int it = 0; it < kMaxIterations; ++it) {
        m.residuals(x, set, r);
        const Eigen::MatrixXd J = jacobian_at(m, x, set, r.size());
        const Eigen::Matrix3d A = J.transpose() * J;
        const Eigen::Vector3d g = J.transpose() * r;
        bool accepted = false;
        for (int tries = 0; tries < 10 && !accepted; ++tries) {
            Eigen::Matrix3d D = A;
            D.diagonal() += lambda * A.diagonal().cwiseMax(1e-12);
            Eigen::Vector3d xn = x + D.ldlt().solve(-g);
            xn(2) = std::clamp(xn(2), std::log(lo), std::log(hi));
            const double c = m.sse(xn, set);
            if (std::isfinite(c) && c <= cost) {
                const bool converged = (xn - x).norm() < 1e-10 || cost - c <= 1e-15 * cost;
                x = xn;
                cost = c;
                lambda = std::max(lambda / 3, 1e-12);
                accepted = true;
                if (converged) return x;
            } else {
                lambda *= 4;
            }
        }
        if (!accepted) return x;
    }
    return x;
}

// Lambert's SSE on `set` (3 parameters, g by least squares), for the comparison.
double lambert_sse(const RoughPixelProblem& p, std::uint32_t set) {
    const auto& lights = *p.lights;
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < lights.size(); ++j)
        if (set & (1U << j)) {
            M += lights[j] * lights[j].transpose();
            b += p.value[j] * lights[j];
        }
    const Eigen::Vector3d g = M.ldlt().solve(b);
    double sse = 0.0;
    for (std::size_t j = 0; j < lights.size(); ++j)
        if (set & (1U << j)) sse += std::pow(p.value[j] - g.dot(lights[j]), 2);
    return sse;
}

double aic(double sse, int m, int parameters) {
    return m * std::log(std::max(sse / m, kTinyVariance)) + 2.0 * parameters;
}

}  // namespace

RoughPixelFit fit_rough_pixel(const RoughPixelProblem& p) {
    RoughPixelFit f;
    const Model model(p);
    std::uint32_t set = p.set;
    const auto& lights = *p.lights;
    for (;;) {
        const int m = std::popcount(set);
        if (m < 4) return f;
        // Start: the Lambertian normal and the best σ/T of a log scan.
        Eigen::Vector3d x(0.0, 0.0, 0.0);
        double best = std::numeric_limits<double>::infinity();
        for (int k = 0; k < kScan; ++k) {
            const double t =
                std::log(p.min_sigma_over_T) +
                (std::log(p.max_sigma_over_T) - std::log(p.min_sigma_over_T)) * (k + 0.5) / kScan;
            const double c = model.sse(Eigen::Vector3d(0.0, 0.0, t), set);
            if (c < best) {
                best = c;
                x(2) = t;
            }
        }
        x = minimise(model, x, set, p.min_sigma_over_T, p.max_sigma_over_T);
        Eigen::VectorXd r;
        const double rho = model.residuals(x, set, r);
        if (!(rho > 0.0)) return f;
        std::array<double, 32> b{};
        model.brightness(x, set, b);
        double brightest = 0.0;
        int worst = -1;
        double worst_excess = 0.0;
        for (std::size_t j = 0; j < lights.size(); ++j) {
            if (!(set & (1U << j))) continue;
            brightest = std::max(brightest, rho * b[j]);
            if (r(static_cast<Eigen::Index>(j)) > worst_excess) {
                worst_excess = r(static_cast<Eigen::Index>(j));
                worst = static_cast<int>(j);
            }
        }
        if (m >= 5 && worst >= 0 && worst_excess > p.highlight_fraction * brightest) {
            set &= ~(1U << static_cast<unsigned>(worst));
            ++f.highlights;
            continue;
        }
        const double sse = r.squaredNorm();
        f.ok = true;
        f.set = set;
        f.normal = model.normal(x);
        f.albedo = rho;
        f.sigma_over_T = std::exp(x(2));
        f.residual_rel = brightest > 0.0 ? std::sqrt(sse / m) / brightest : kNaN;
        f.sigma_over_T_stderr = kNaN;
        f.delta_aic = kNaN;
        if (m >= 5) {
            const Eigen::MatrixXd J = jacobian_at(model, x, set, r.size());
            const Eigen::Matrix3d A = J.transpose() * J;
            Eigen::Matrix3d cov = A.completeOrthogonalDecomposition().pseudoInverse();
            cov *= sse / (m - 4);
            f.sigma_over_T_stderr = f.sigma_over_T * std::sqrt(std::max(cov(2, 2), 0.0));
            f.delta_aic = aic(lambert_sse(p, set), m, 3) - aic(sse, m, 4);
        }
        return f;
    }
}

}  // namespace roughscope::image::detail
