/// \file
/// \brief Fixed-size Eigen aliases used throughout kelp (never added to `namespace Eigen`).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kelp {

template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Vector6 = Eigen::Matrix<Scalar, 6, 1>;
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
template <typename Scalar>
using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
template <typename Scalar>
using Matrix3X = Eigen::Matrix<Scalar, 3, Eigen::Dynamic>;
template <typename Scalar>
using VectorX = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
template <typename Scalar>
using Quaternion = Eigen::Quaternion<Scalar>;

}  // namespace kelp
