#pragma once
// The linear-algebra vocabulary of pwl: Eigen's dynamic types for everything of run-time size.
#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace pwl {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor>;
using Index = Eigen::Index;

}  // namespace pwl
