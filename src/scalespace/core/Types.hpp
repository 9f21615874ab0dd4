#pragma once
// Basic numeric types shared by every layer.
#include <Eigen/Core>
#include <cstdint>

namespace scalespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Index = std::uint32_t;  // point index: clouds up to 4 billion points

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace scalespace
