#pragma once
// The type vocabulary Eigen's unsupported Levenberg–Marquardt and NumericalDiff expect of a
// residual functor, for problems whose sizes are known only at run time. Derive from it and
// add inputs(), values() and int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r).
// Header only; the user links Eigen.

#include <Eigen/Core>

namespace sedbridge::common {

struct DynamicSizeFunctor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
};

}  // namespace sedbridge::common
