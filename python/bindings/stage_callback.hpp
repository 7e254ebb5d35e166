#pragma once
// A Python callable as the core's on_stage callback: the core calls it on the calling thread with
// the GIL released, so the GIL is taken back for the call only. None gives an empty callback.
#include <pybind11/pybind11.h>

#include <functional>

// `on_stage` must outlive the returned function (the binding's argument does: the call runs inside it).
inline std::function<void(const char*)> stage_callback(const pybind11::object& on_stage) {
  if (on_stage.is_none()) return {};
  return [&on_stage](const char* stage) {
    pybind11::gil_scoped_acquire acquire;
    on_stage(stage);
  };
}
