// Levelling: the least-squares mean, mean line (per row), plane and polynomial background of a
// height map over its valid points (paper §3.1: heights are measured from the least-squares mean
// line). Definitions: docs/surface.md.
#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "roughscope/core/errors.hpp"
#include "roughscope/surface/statistics.hpp"

namespace roughscope::surface {
namespace {

// Coordinate of sample i of n scaled to [−1, 1] (0 for n = 1): keeps the normal equations of a
// cubic well conditioned whatever the map size.
double scaled(std::size_t i, std::size_t n) {
    return n > 1 ? 2.0 * static_cast<double>(i) / static_cast<double>(n - 1) - 1.0 : 0.0;
}

void subtract_mean(HeightMap& map) {
    double sum = 0;
    std::size_t count = 0;
    for (double z : map.heights_um)
        if (!std::isnan(z)) {
            sum += z;
            ++count;
        }
    if (count == 0) throw InvalidArgument("level: the map has no valid point to take a mean of");
    const double mean = sum / static_cast<double>(count);
    for (double& z : map.heights_um) z -= mean;  // NaN stays NaN
}

// Each row minus its own least-squares line a + b·u over its valid points; a row with one valid
// point loses its value (mean), a row with none is left missing.
void subtract_row_lines(HeightMap& map) {
    bool any_line = false;
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        double* row = &map.heights_um[iy * map.nx];
        double n = 0, su = 0, suu = 0, sz = 0, suz = 0;
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            const double z = row[ix];
            if (std::isnan(z)) continue;
            const double u = scaled(ix, map.nx);
            n += 1;
            su += u;
            suu += u * u;
            sz += z;
            suz += u * z;
        }
        if (n == 0) continue;
        double a = sz / n;
        double b = 0;
        const double det = n * suu - su * su;
        if (n >= 2 && det > 1e-12 * n * n) {
            any_line = true;
            b = (n * suz - su * sz) / det;
            a = (sz - b * su) / n;
        }
        for (std::size_t ix = 0; ix < map.nx; ++ix) row[ix] -= a + b * scaled(ix, map.nx);
    }
    if (!any_line)
        throw InvalidArgument(
            "level: line levelling needs a row with at least 2 valid points; no row of the " +
            std::to_string(map.nx) + " x " + std::to_string(map.ny) + " map has them");
}

// Map minus the least-squares polynomial Σ c_ij u^i v^j, i + j ≤ order (j = 0 for a profile).
// The normal equations are assembled row by row from the row sums Σ u^a and Σ u^a z, so one pass
// over the map costs a few operations a point whatever the order.
void subtract_polynomial(HeightMap& map, int order) {
    const bool profile = map.is_profile();
    struct Term {
        std::size_t i, j;  // powers of u and v
    };
    std::vector<Term> terms;
    const auto max_order = static_cast<std::size_t>(order);
    for (std::size_t total = 0; total <= max_order; ++total)
        for (std::size_t j = 0; j <= (profile ? 0 : total); ++j) terms.push_back({total - j, j});
    const auto nt = static_cast<Eigen::Index>(terms.size());

    const std::size_t max_pow = 2 * max_order;
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(nt, nt);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nt);
    std::size_t count = 0;
    std::array<double, 7> pu{};   // Σ u^a over a row's valid points, a ≤ 6
    std::array<double, 4> puz{};  // Σ u^a z, a ≤ 3
    std::array<double, 7> vpow{};
    std::vector<double> u_of(map.nx);
    for (std::size_t ix = 0; ix < map.nx; ++ix) u_of[ix] = scaled(ix, map.nx);
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        pu.fill(0);
        puz.fill(0);
        const double* row = &map.heights_um[iy * map.nx];
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            const double z = row[ix];
            if (std::isnan(z)) continue;
            ++count;
            const double u = u_of[ix];
            double p = 1;
            for (std::size_t a = 0; a <= max_pow; ++a) {
                pu[a] += p;
                if (a <= max_order) puz[a] += p * z;
                p *= u;
            }
        }
        if (pu[0] == 0) continue;
        const double v = scaled(iy, map.ny);
        vpow[0] = 1;
        for (std::size_t b = 1; b < vpow.size(); ++b) vpow[b] = vpow[b - 1] * v;
        for (Eigen::Index r = 0; r < nt; ++r) {
            const Term tr = terms[static_cast<std::size_t>(r)];
            rhs(r) += vpow[tr.j] * puz[tr.i];
            for (Eigen::Index c = 0; c < nt; ++c) {
                const Term tc = terms[static_cast<std::size_t>(c)];
                normal(r, c) += vpow[tr.j + tc.j] * pu[tr.i + tc.i];
            }
        }
    }
    const std::string what =
        order == 1 ? std::string("plane") : "polynomial of order " + std::to_string(order);
    if (count < terms.size())
        throw InvalidArgument("level: the least-squares " + what + " needs at least " +
                              std::to_string(terms.size()) + " valid points; the map has " +
                              std::to_string(count));
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(normal);
    qr.setThreshold(1e-10);
    if (qr.rank() < nt)
        throw InvalidArgument("level: the " + std::to_string(count) +
                              " valid points do not determine a least-squares " + what +
                              " (they lie on too few rows or columns)");
    const Eigen::VectorXd c = qr.solve(rhs);

    std::array<double, 4> row_coef{};  // coefficients of u^i in the current row
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        const double v = scaled(iy, map.ny);
        row_coef.fill(0);
        for (Eigen::Index t = 0; t < nt; ++t) {
            const Term term = terms[static_cast<std::size_t>(t)];
            row_coef[term.i] += c(t) * std::pow(v, static_cast<double>(term.j));
        }
        double* row = &map.heights_um[iy * map.nx];
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            const double u = u_of[ix];
            row[ix] -= row_coef[0] + u * (row_coef[1] + u * (row_coef[2] + u * row_coef[3]));
        }
    }
}

}  // namespace

HeightMap level(HeightMap map, Leveling leveling, int polynomial_order) {
    validate(map, "heights");
    if (leveling == Leveling::Polynomial && (polynomial_order < 1 || polynomial_order > 3))
        throw InvalidArgument("level: polynomial_order = " + std::to_string(polynomial_order) +
                              " is out of range; valid values: 1, 2, 3");
    HeightMap out = std::move(map);
    switch (leveling) {
        case Leveling::None:
            break;
        case Leveling::Mean:
            subtract_mean(out);
            break;
        case Leveling::Line:
            subtract_row_lines(out);
            break;
        case Leveling::Plane:
            subtract_polynomial(out, 1);
            break;
        case Leveling::Polynomial:
            subtract_polynomial(out, polynomial_order);
            break;
    }
    return out;
}

}  // namespace roughscope::surface
