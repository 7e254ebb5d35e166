#pragma once
// The methods of a field cross as small integer codes with the table of their names, so that
// Python never decodes them by a list of its own.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <morphomap/field.hpp>

#include <vector>

inline pybind11::tuple method_codes(const std::vector<morphomap::Method>& methods) {
  pybind11::array_t<std::int8_t> codes(static_cast<pybind11::ssize_t>(methods.size()));
  auto out = codes.mutable_unchecked<1>();
  for (std::size_t i = 0; i < methods.size(); ++i) out(static_cast<pybind11::ssize_t>(i)) = static_cast<std::int8_t>(methods[i]);
  pybind11::list names;
  for (int code = 0; code < morphomap::kMethodCount; ++code) {
    names.append(morphomap::method_name(static_cast<morphomap::Method>(code)));
  }
  return pybind11::make_tuple(codes, names);
}
