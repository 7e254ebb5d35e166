#pragma once
// Everything of the public C++ API.
#include <morphomap/build_info.hpp>
#include <morphomap/crossings.hpp>
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/field.hpp>
#include <morphomap/interrupt.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/laplace3d.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/quality.hpp>
#include <morphomap/resample.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>
#include <morphomap/transform.hpp>
#include <morphomap/types.hpp>
