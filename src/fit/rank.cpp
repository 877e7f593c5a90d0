// The linear algebra of a fit's identifiability test and covariance (rank.hpp).
#include "rank.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace roughscope::detail {

// The upper-triangular factor R (p×p) of the thin QR decomposition J = QR of a tall J (rows ≥
// columns), computed in place: J is overwritten (and released by the caller's reassignment).
Eigen::MatrixXd triangular_factor(Eigen::MatrixXd& J) {
    const Eigen::Index p = J.cols();
    const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(J);
    return qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
}

// Identifiability of the columns `cols` of J: the names of the parameters that the data do not
// determine (empty when J restricted to cols has full column rank).
std::vector<int> unidentified(const Eigen::MatrixXd& J, const std::vector<int>& cols, double tol) {
    std::vector<int> bad;
    if (cols.empty()) return bad;
    Eigen::VectorXd norms(static_cast<Eigen::Index>(cols.size()));
    for (std::size_t a = 0; a < cols.size(); ++a)
        norms(static_cast<Eigen::Index>(a)) = J.col(cols[a]).norm();
    const double max_norm = norms.maxCoeff();
    std::vector<int> live;
    for (std::size_t a = 0; a < cols.size(); ++a) {
        if (!(norms(static_cast<Eigen::Index>(a)) > tol * max_norm))
            bad.push_back(cols[a]);  // no effect on the residuals
        else
            live.push_back(cols[a]);
    }
    if (live.size() >= 2) {
        Eigen::MatrixXd S(J.rows(), static_cast<Eigen::Index>(live.size()));
        for (std::size_t a = 0; a < live.size(); ++a)
            S.col(static_cast<Eigen::Index>(a)) = J.col(live[a]) / J.col(live[a]).norm();
        Eigen::JacobiSVD<Eigen::MatrixXd> svd(S, Eigen::ComputeThinV);
        const Eigen::VectorXd& sv = svd.singularValues();
        const Eigen::MatrixXd& V = svd.matrixV();
        std::vector<bool> flagged(live.size(), false);
        for (Eigen::Index k = 0; k < sv.size(); ++k) {
            if (sv(k) > tol * sv(0)) continue;
            for (std::size_t a = 0; a < live.size(); ++a)
                if (std::abs(V(static_cast<Eigen::Index>(a), k)) >= 0.1) flagged[a] = true;
        }
        for (std::size_t a = 0; a < live.size(); ++a)
            if (flagged[a]) bad.push_back(live[a]);
    }
    std::sort(bad.begin(), bad.end());
    return bad;
}

// (JᵀJ)⁻¹ over the columns `cols` (others zero), from an SVD; false when rank deficient.
bool inverse_normal_matrix(const Eigen::MatrixXd& J, const std::vector<int>& cols,
                           Eigen::MatrixXd& C) {
    C.setZero(J.cols(), J.cols());
    if (cols.empty()) return true;
    Eigen::MatrixXd S(J.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t a = 0; a < cols.size(); ++a)
        S.col(static_cast<Eigen::Index>(a)) = J.col(cols[a]);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(S, Eigen::ComputeThinV);
    const Eigen::VectorXd& sv = svd.singularValues();
    if (!(sv(sv.size() - 1) > 1e-12 * sv(0))) return false;
    const Eigen::VectorXd inv2 = sv.array().square().inverse();
    const Eigen::MatrixXd Cs = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
    for (std::size_t a = 0; a < cols.size(); ++a)
        for (std::size_t b = 0; b < cols.size(); ++b)
            C(cols[a], cols[b]) = Cs(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    return C.allFinite();
}

}  // namespace roughscope::detail
