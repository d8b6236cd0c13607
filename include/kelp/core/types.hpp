/// \file
/// \brief Fixed-size Eigen aliases used throughout kelp (never added to `namespace Eigen`).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kelp {

/// \brief A 3-vector (a position, velocity or force; its frame is the variable's, NED or body).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
/// \brief A 6-vector: a pose (x, y, z, φ, θ, ψ), a body velocity ν = (u, v, w, p, q, r) or a
/// wrench τ = (X, Y, Z, K, M, N) (Fossen 2021's order: linear part first).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Vector6 = Eigen::Matrix<Scalar, 6, 1>;
/// \brief A 3×3 matrix (a rotation, an inertia tensor).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
/// \brief A 6×6 matrix (mass, Coriolis, damping, a kinematic transformation).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Matrix6 = Eigen::Matrix<Scalar, 6, 6>;
/// \brief A 3×N matrix: one column per point (a tether's node positions or velocities).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Matrix3X = Eigen::Matrix<Scalar, 3, Eigen::Dynamic>;
/// \brief A vector of any length (thruster commands or forces).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using VectorX = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
/// \brief A quaternion; kelp's attitudes are unit quaternions rotating body vectors into NED.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
using Quaternion = Eigen::Quaternion<Scalar>;

}  // namespace kelp
