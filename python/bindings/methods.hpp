#pragma once
// A displacement field crosses as a dict keyed by the C++ field names; its methods as small
// integer codes with the core's table of their names, so that Python never decodes them by a list
// of its own.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <morphomap/field.hpp>

#include <vector>

inline pybind11::dict method_codes(const std::vector<morphomap::Method>& methods) {
  pybind11::array_t<std::int8_t> codes(static_cast<pybind11::ssize_t>(methods.size()));
  auto out = codes.mutable_unchecked<1>();
  for (std::size_t i = 0; i < methods.size(); ++i)
    out(static_cast<pybind11::ssize_t>(i)) = static_cast<std::int8_t>(methods[i]);
  pybind11::list names;
  for (int code = 0; code < morphomap::kMethodCount; ++code) {
    names.append(morphomap::method_name(static_cast<morphomap::Method>(code)));
  }
  return pybind11::dict(pybind11::arg("codes") = codes, pybind11::arg("names") = names);
}

inline pybind11::dict field_record(morphomap::DisplacementField2&& field) {
  return pybind11::dict(pybind11::arg("starts") = std::move(field.starts),
                        pybind11::arg("ends") = std::move(field.ends),
                        pybind11::arg("methods") = method_codes(field.methods));
}

inline pybind11::dict field_record(morphomap::DisplacementField3&& field) {
  return pybind11::dict(
      pybind11::arg("starts") = std::move(field.starts), pybind11::arg("ends") = std::move(field.ends),
      pybind11::arg("methods") = method_codes(field.methods), pybind11::arg("faces") = std::move(field.faces));
}
