// The linear algebra of a fit's identifiability test and covariance (src/fit/engine.cpp): the
// triangular factor of a Jacobian, its rank over chosen columns, and (JᵀJ)⁻¹. Internal to the fit
// topic.
#pragma once

#include <vector>

#include <Eigen/Dense>

namespace roughscope::detail {

// The upper-triangular factor R (p×p) of the thin QR decomposition J = QR of a tall J (rows ≥
// columns), computed in place: J is overwritten (and released by the caller's reassignment).
Eigen::MatrixXd triangular_factor(Eigen::MatrixXd& J);

// Identifiability of the columns `cols` of J: the indices of the parameters that the data do not
// determine (empty when J restricted to cols has full column rank); `tol` is the relative size
// below which a column norm or singular value counts as zero.
std::vector<int> unidentified(const Eigen::MatrixXd& J, const std::vector<int>& cols, double tol);

// (JᵀJ)⁻¹ over the columns `cols` (others zero), from an SVD; false when rank deficient.
bool inverse_normal_matrix(const Eigen::MatrixXd& J, const std::vector<int>& cols,
                           Eigen::MatrixXd& C);

}  // namespace roughscope::detail
