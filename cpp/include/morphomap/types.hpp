#pragma once
// Array types of the public API: row-major so that numpy arrays map onto them without copies.
#include <Eigen/Core>
#include <cstdint>

namespace morphomap {

using Index = std::int64_t;
using Vec2 = Eigen::Vector2d;
using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Vector = Eigen::VectorXd;
using IndexVector = Eigen::Matrix<Index, Eigen::Dynamic, 1>;
using Faces = Eigen::Matrix<Index, Eigen::Dynamic, 3, Eigen::RowMajor>;  // triangles
using Tetrahedra = Eigen::Matrix<Index, Eigen::Dynamic, 4, Eigen::RowMajor>;

// Read-only views that accept any matching Eigen expression or mapped buffer.
using Points2Ref = Eigen::Ref<const Points2>;
using Points3Ref = Eigen::Ref<const Points3>;
using FacesRef = Eigen::Ref<const Faces>;
using TetrahedraRef = Eigen::Ref<const Tetrahedra>;

}  // namespace morphomap
