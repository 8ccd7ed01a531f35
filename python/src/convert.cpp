// SPDX-License-Identifier: BSD-2-Clause
#include "python/src/convert.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/geodesy.hpp"

namespace pednav::python {

using namespace pybind11::literals;

void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A plain YAML scalar as the YAML 1.2 core schema reads it.
py::object plain_scalar(const std::string& s) {
  if (s == "true" || s == "True" || s == "TRUE") return py::bool_(true);
  if (s == "false" || s == "False" || s == "FALSE") return py::bool_(false);
  if (s.empty() || s == "~" || s == "null" || s == "Null" || s == "NULL") return py::none();
  if (s == ".inf" || s == "+.inf" || s == ".Inf") return py::float_(std::numeric_limits<double>::infinity());
  if (s == "-.inf" || s == "-.Inf") return py::float_(-std::numeric_limits<double>::infinity());
  if (s == ".nan" || s == ".NaN") return py::float_(kNaN);
  const char* b = s.c_str();
  char* end = nullptr;
  errno = 0;
  const long long i = std::strtoll(b, &end, 10);
  if (errno == 0 && end != b && *end == '\0') return py::int_(i);
  const bool numeric_chars = s.find_first_not_of("0123456789+-.eE") == std::string::npos;
  if (numeric_chars) {
    errno = 0;
    const double d = std::strtod(b, &end);
    if (errno == 0 && end != b && *end == '\0') return py::float_(d);
  }
  return py::str(s);
}

void emit(YAML::Emitter& e, const py::handle& obj, const std::string& path) {
  if (obj.is_none()) {
    e << YAML::Null;
  } else if (py::isinstance<py::bool_>(obj)) {
    e << (obj.cast<bool>() ? "true" : "false");
  } else if (py::isinstance<py::int_>(obj)) {
    e << std::to_string(obj.cast<long long>());
  } else if (py::isinstance<py::float_>(obj) || py::isinstance(obj, py::module_::import("numpy").attr("floating"))) {
    const double v = obj.cast<double>();
    e << (std::isnan(v) ? std::string(".nan") : std::isinf(v) ? std::string(v > 0 ? ".inf" : "-.inf")
                                                               : fmt::format("{}", v));
  } else if (py::isinstance(obj, py::module_::import("numpy").attr("integer"))) {
    e << std::to_string(obj.cast<long long>());
  } else if (py::isinstance<py::str>(obj)) {
    e << YAML::DoubleQuoted << obj.cast<std::string>();
  } else if (py::isinstance<py::dict>(obj)) {
    e << YAML::BeginMap;
    for (const auto& kv : obj.cast<py::dict>()) {
      if (!py::isinstance<py::str>(kv.first)) {
        raise(PyExc_ValueError, (path.empty() ? std::string("config") : path) + ": keys must be str, got " +
                                    py::repr(kv.first).cast<std::string>());
      }
      const std::string key = kv.first.cast<std::string>();
      e << YAML::Key << key << YAML::Value;
      emit(e, kv.second, path.empty() ? key : path + "." + key);
    }
    e << YAML::EndMap;
  } else if (py::isinstance<py::list>(obj) || py::isinstance<py::tuple>(obj) ||
             py::isinstance<py::array>(obj)) {
    e << YAML::BeginSeq;
    size_t i = 0;
    for (const auto& item : obj) emit(e, item, path + "[" + std::to_string(i++) + "]");
    e << YAML::EndSeq;
  } else {
    raise(PyExc_ValueError, (path.empty() ? std::string("config") : path) + ": cannot be written as YAML (" +
                                py::str(py::type::of(obj)).cast<std::string>() + ")");
  }
}

}  // namespace

py::object yaml_to_py(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      py::dict d;
      for (const auto& kv : node) d[py::str(kv.first.Scalar())] = yaml_to_py(kv.second);
      return d;
    }
    case YAML::NodeType::Sequence: {
      py::list l;
      for (const auto& item : node) l.append(yaml_to_py(item));
      return l;
    }
    case YAML::NodeType::Scalar:
      return node.Tag() == "!" ? py::object(py::str(node.Scalar())) : plain_scalar(node.Scalar());
    default:
      return py::none();
  }
}

std::string py_to_yaml(const py::handle& obj, const std::string& path) {
  YAML::Emitter e;
  emit(e, obj, path);
  return std::string(e.c_str()) + "\n";
}

py::object json_to_py(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }
py::object json_to_py(const nlohmann::ordered_json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::array_t<double> float_array(const py::handle& obj, const std::string& name, py::ssize_t cols, bool finite) {
  const std::string expected = cols == 0 ? "(N,)" : "(N, " + std::to_string(cols) + ")";
  py::module_ np = py::module_::import("numpy");
  py::object arr;
  try {
    arr = np.attr("asarray")(obj);
  } catch (py::error_already_set& e) {
    raise(PyExc_ValueError, name + ": not an array of numbers (" + std::string(e.what()) + ")");
  }
  const std::string kind = arr.attr("dtype").attr("kind").cast<std::string>();
  if (kind != "f" && kind != "i" && kind != "u") {
    raise(PyExc_ValueError, name + ": dtype " + py::str(arr.attr("dtype")).cast<std::string>() +
                                " is not a real number type (float or int expected)");
  }
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(arr);
  if (!a) raise(PyExc_ValueError, name + ": cannot be converted to float64");
  const bool shape_ok = cols == 0 ? a.ndim() == 1 : a.ndim() == 2 && a.shape(1) == cols;
  if (!shape_ok) {
    std::string shape = "(";
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    shape += a.ndim() == 1 ? ",)" : ")";
    raise(PyExc_ValueError, name + ": shape " + shape + ", expected " + expected);
  }
  if (finite) {
    const double* p = a.data();
    const py::ssize_t n = a.size();
    for (py::ssize_t k = 0; k < n; ++k) {
      if (std::isfinite(p[k])) continue;
      const std::string where = cols == 0 ? "[" + std::to_string(k) + "]"
                                          : "[" + std::to_string(k / cols) + ", " + std::to_string(k % cols) + "]";
      raise(PyExc_ValueError, name + where + " is " + (std::isnan(p[k]) ? "NaN" : "infinite") + " (finite values expected)");
    }
  }
  return a;
}

py::dict solution_columns(const std::vector<io::SolutionRow>& rows) {
  const auto n = static_cast<py::ssize_t>(rows.size());
  const bool carrier = std::any_of(rows.begin(), rows.end(), [](const io::SolutionRow& r) { return r.solution_status; });
  std::vector<std::string> names;
  {
    std::stringstream header(io::solution_csv_header(carrier));
    for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  }
  py::dict d;
  std::vector<py::array_t<double>> cols;
  for (const auto& name : names) {
    if (name == "solution_status") continue;
    cols.emplace_back(n);
  }
  py::list status;
  for (py::ssize_t k = 0; k < n; ++k) {
    const io::SolutionRow& r = rows[static_cast<size_t>(k)];
    const Geodetic llh = geodetic_from_ecef(r.p_e);
    // Column order of io::solution_csv_header (status column kept apart: a str array).
    const double v[] = {static_cast<double>(r.time.week()),
                        r.time.tow_s(),
                        llh.lat * kRadToDeg,
                        llh.lon * kRadToDeg,
                        llh.h_m,
                        r.p_e.x(),
                        r.p_e.y(),
                        r.p_e.z(),
                        r.v_n ? (*r.v_n)(0) : kNaN,
                        r.v_n ? (*r.v_n)(1) : kNaN,
                        r.v_n ? (*r.v_n)(2) : kNaN,
                        r.rpy_deg ? (*r.rpy_deg)(0) : kNaN,
                        r.rpy_deg ? (*r.rpy_deg)(1) : kNaN,
                        r.rpy_deg ? (*r.rpy_deg)(2) : kNaN,
                        std::sqrt(std::max(0.0, r.cov_p_n(0, 0))),
                        std::sqrt(std::max(0.0, r.cov_p_n(1, 1))),
                        std::sqrt(std::max(0.0, r.cov_p_n(2, 2))),
                        r.sd_yaw_deg ? *r.sd_yaw_deg : kNaN,
                        static_cast<double>(r.n_sats_used),
                        static_cast<double>(r.n_sats_rejected),
                        r.zupt ? (*r.zupt ? 1.0 : 0.0) : kNaN,
                        r.hdop ? *r.hdop : kNaN,
                        r.pdop ? *r.pdop : kNaN,
                        r.solution_status ? static_cast<double>(r.n_fixed_ambiguities) : kNaN,
                        r.solution_status ? r.ar_ratio : kNaN};
    for (size_t c = 0; c < cols.size(); ++c) cols[c].mutable_at(k) = v[c];
    if (carrier) status.append(r.solution_status ? py::str(r.solution_status) : py::str(""));
  }
  size_t c = 0;
  for (const auto& name : names) {
    if (name == "solution_status") {
      d[py::str(name)] = py::module_::import("numpy").attr("array")(status, "dtype"_a = "U5");
      continue;
    }
    py::array_t<double>& a = cols[c++];
    // Integer columns as int64 (gps_week, counts); zupt as int8 (1 stance, 0 not).
    if (name == "gps_week" || name == "n_sats_used" || name == "n_sats_rejected" || name == "n_fixed_ambiguities") {
      d[py::str(name)] = a.attr("astype")("int64");
    } else if (name == "zupt") {
      d[py::str(name)] = a.attr("astype")("int8");
    } else {
      d[py::str(name)] = a;
    }
  }
  return d;
}

py::dict read_csv_columns(const std::string& path) {
  std::ifstream f(path);
  if (!f) raise(PyExc_FileNotFoundError, path + ": cannot open");
  std::string line;
  if (!std::getline(f, line)) raise(PyExc_ValueError, path + ": empty file (a header row expected)");
  std::vector<std::string> names;
  {
    std::stringstream header(line);
    for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  }
  std::vector<std::vector<std::string>> cells(names.size());
  long line_no = 1;
  while (std::getline(f, line)) {
    ++line_no;
    if (line.empty()) continue;
    std::stringstream row(line);
    size_t c = 0;
    for (std::string cell; std::getline(row, cell, ',') && c < names.size(); ++c) cells[c].push_back(cell);
    for (; c < names.size(); ++c) cells[c].emplace_back();
  }
  py::dict d;
  for (size_t c = 0; c < names.size(); ++c) {
    bool numeric = true;
    std::vector<double> v(cells[c].size());
    for (size_t k = 0; k < cells[c].size() && numeric; ++k) {
      const std::string& s = cells[c][k];
      if (s.empty()) {
        v[k] = kNaN;
        continue;
      }
      char* end = nullptr;
      v[k] = std::strtod(s.c_str(), &end);
      numeric = end != s.c_str() && *end == '\0';
    }
    if (numeric) {
      py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
      std::copy(v.begin(), v.end(), a.mutable_data());
      d[py::str(names[c])] = a;
    } else {
      py::list l;
      for (const auto& s : cells[c]) l.append(py::str(s));
      d[py::str(names[c])] = py::module_::import("numpy").attr("array")(l);
    }
  }
  return d;
}

}  // namespace pednav::python
