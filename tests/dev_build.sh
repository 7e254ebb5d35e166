#!/usr/bin/env bash
# Developer shortcut: build the C++ library, its tests and the Python module in build/dev-NAME and
# lay out an importable package there, so that several people can work in one tree at once.
#   tests/dev_build.sh NAME            then   PYTHONPATH=build/dev-NAME/pkg python3 -m pytest tests
set -euo pipefail
name=${1:?usage: tests/dev_build.sh NAME}
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/dev-$name"
cmake -S "$root" -B "$build" -G Ninja -DMORPHOMAP_BUILD_PYTHON=ON -DMORPHOMAP_BUILD_TESTS=ON \
  -DPython_EXECUTABLE="$(command -v python3)" -Dpybind11_DIR="$(python3 -m pybind11 --cmakedir)" >/dev/null
cmake --build "$build" -j2
rm -rf "$build/pkg" && mkdir -p "$build/pkg"
cp -r "$root/python/morphomap" "$build/pkg/"
cp "$build"/python/_core*.so "$build/pkg/morphomap/"
