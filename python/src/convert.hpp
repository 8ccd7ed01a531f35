// SPDX-License-Identifier: BSD-2-Clause
// Conversions at the Python boundary of the module `pednav` (docs/python.md): Python exceptions with the CLI's
// messages, YAML <-> Python objects, JSON -> Python objects, numpy arrays checked and converted to float64.
// Every function here runs with the GIL held.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/solution_writer.hpp"

namespace pednav::python {

namespace py = pybind11;

/// Raise `type` (PyExc_ValueError, PyExc_FileNotFoundError, PyExc_RuntimeError, ...) with `message`.
[[noreturn]] void raise(PyObject* type, const std::string& message);

/// A YAML document as Python objects: maps -> dict, sequences -> list, plain scalars -> bool / int / float / None
/// when they read as one (YAML 1.2 core schema), else str; quoted scalars -> str.
py::object yaml_to_py(const YAML::Node& node);
/// A Python object (dict, list, tuple, str, bool, int, float, None, numpy scalar) as YAML text (block style);
/// raises ValueError naming `path` for anything else.
std::string py_to_yaml(const py::handle& obj, const std::string& path);

/// A JSON value as Python objects (json.loads of its text: numbers keep every digit).
py::object json_to_py(const nlohmann::json& j);
py::object json_to_py(const nlohmann::ordered_json& j);

/// `obj` as a C-contiguous float64 array of shape (n) (cols == 0) or (n, cols); float32, integer and
/// non-contiguous arrays and nested sequences are converted. ValueError naming `name` for a wrong shape, a
/// non-numeric dtype or a non-finite value (with its index).
py::array_t<double> float_array(const py::handle& obj, const std::string& name, py::ssize_t cols, bool finite = true);

/// solution.csv's columns of `rows` (names of io::solution_csv_header), each a numpy array; the values are those the
/// writer formats (geodetic from ECEF, σ = sqrt of the covariance diagonal), empty cells as NaN.
py::dict solution_columns(const std::vector<io::SolutionRow>& rows);

/// A CSV file with a header row as columns: numbers -> float64 arrays, other columns -> arrays of str.
py::dict read_csv_columns(const std::string& path);

}  // namespace pednav::python
