// SPDX-License-Identifier: BSD-2-Clause
// Config and ImuLog of the Python module (python/src/inputs.hpp).
#include "python/src/inputs.hpp"

#include <pybind11/stl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cctype>
#include <filesystem>

#include "eval/statistics.hpp"
#include "io/yaml_schema.hpp"
#include "pipeline/run_command.hpp"
#include "python/src/convert.hpp"

namespace pednav::python {

using namespace pybind11::literals;
namespace fs = std::filesystem;

std::mutex& rtklib_mutex() {
  static std::mutex m;
  return m;
}

// ---------------------------------------------------------------------------------------------------------------
// Config


/// What `pednav config-check` reports for `c`: the run problems raise ValueError, missing input files
/// FileNotFoundError; each line "<source>: <problem>", as the CLI prints them.
void check_config(const io::RunConfig& c) {
  std::string bad, missing;
  for (const auto& m : pipeline::run_config_problems(c)) bad += (bad.empty() ? "" : "\n") + c.source_file + ": " + m;
  if (!bad.empty()) raise(PyExc_ValueError, bad);
  for (const auto& m : io::missing_input_files(c)) missing += (missing.empty() ? "" : "\n") + c.source_file + ": " + m;
  if (!missing.empty()) raise(PyExc_FileNotFoundError, missing);
}

/// A file name argument: str or os.PathLike.
std::string path_of(const py::handle& obj) {
  return py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>();
}

Config config_from_yaml(const py::object& path_obj) {
  io::RunConfig c = read_file_or_raise(path_of(path_obj), [](const std::string& p) { return io::load_run_config(p); });
  check_config(c);
  return Config{std::make_shared<const io::RunConfig>(std::move(c))};
}

// "config:<digits>: " at the start of a line → "config: ".
static std::string drop_config_line_numbers(const std::string& message) {
  std::string out;
  size_t i = 0;
  while (i < message.size()) {
    const size_t eol = message.find('\n', i);
    std::string line = message.substr(i, eol == std::string::npos ? std::string::npos : eol - i + 1);
    const std::string lead = "config:";
    if (line.compare(0, lead.size(), lead) == 0) {
      size_t d = lead.size();
      while (d < line.size() && std::isdigit(static_cast<unsigned char>(line[d]))) ++d;
      if (d > lead.size() && line.compare(d, 2, ": ") == 0) line = "config: " + line.substr(d + 2);
    }
    out += line;
    if (eol == std::string::npos) break;
    i = eol + 1;
  }
  return out;
}

Config config_from_dict(const py::dict& d, const std::optional<std::string>& base_dir) {
  const std::string text = py_to_yaml(d, "");
  const std::string dir = base_dir ? *base_dir : fs::current_path().string();
  auto c = io::parse_run_config(text, "config", dir);
  if (!c) {
    // The messages name the key path; the line numbers would be those of the YAML made from the dict: dropped.
    raise(PyExc_ValueError, drop_config_line_numbers(c.error().message));
  }
  check_config(*c);
  return Config{std::make_shared<const io::RunConfig>(std::move(*c))};
}

py::object config_to_dict(const Config& c) { return yaml_to_py(YAML::Load(io::to_yaml(*c.c))); }

// ---------------------------------------------------------------------------------------------------------------
// ImuLog


// Seconds of a time since the start of GPS week `week`.
double seconds_of_week(GpsTime t, int week) {
  constexpr int64_t kNsPerSecond = 1000000000LL;
  const int64_t ns = t.ns() - static_cast<int64_t>(week) * 604800LL * kNsPerSecond;
  return static_cast<double>(ns / kNsPerSecond) + static_cast<double>(ns % kNsPerSecond) * 1e-9;  // as GpsTime::tow_s
}

ImuLog imu_from_arrays(const py::handle& t_obj, const py::handle& gyro_obj, const py::handle& accel_obj,
                       const py::object& stance_obj, int gps_week) {
  const auto t = float_array(t_obj, "t_s", 0);
  const auto gyro = float_array(gyro_obj, "gyro_radps", 3);
  const auto accel = float_array(accel_obj, "accel_mps2", 3);
  const py::ssize_t n = t.shape(0);
  if (n == 0) raise(PyExc_ValueError, "t_s: empty (no IMU samples)");
  if (gyro.shape(0) != n || accel.shape(0) != n) {
    raise(PyExc_ValueError, "gyro_radps and accel_mps2 need one row per time stamp: " + std::to_string(n) +
                                " time stamps, " + std::to_string(gyro.shape(0)) + " and " +
                                std::to_string(accel.shape(0)) + " rows");
  }
  if (gps_week < 0) raise(PyExc_ValueError, "gps_week: " + std::to_string(gps_week) + " is negative");
  auto log = std::make_shared<io::ImuLog>();
  log->samples.resize(static_cast<size_t>(n));
  const double* tp = t.data();
  const double* gp = gyro.data();
  const double* ap = accel.data();
  for (py::ssize_t k = 0; k < n; ++k) {
    if (k > 0 && !(tp[k] > tp[k - 1])) {
      raise(PyExc_ValueError, fmt::format("t_s[{}]: time {:.6f} s is not after the previous {:.6f} s (strictly "
                                          "increasing times expected)", k, tp[k], tp[k - 1]));
    }
    ins::ImuSample& s = log->samples[static_cast<size_t>(k)];
    s.t = GpsTime::from_week_tow(gps_week, tp[k]);
    s.omega_ib_b = Eigen::Vector3d(gp[3 * k], gp[3 * k + 1], gp[3 * k + 2]);
    s.f_ib_b = Eigen::Vector3d(ap[3 * k], ap[3 * k + 1], ap[3 * k + 2]);
  }
  if (!stance_obj.is_none()) {
    const auto st = float_array(stance_obj, "stance_label", 0);
    if (st.shape(0) != n) {
      raise(PyExc_ValueError, "stance_label: " + std::to_string(st.shape(0)) + " labels for " + std::to_string(n) +
                                  " samples");
    }
    log->stance.resize(static_cast<size_t>(n));
    for (py::ssize_t k = 0; k < n; ++k) {
      const double v = st.data()[k];
      if (v != 0.0 && v != 1.0) raise(PyExc_ValueError, fmt::format("stance_label[{}] is {} (0 or 1 expected)", k, v));
      log->stance[static_cast<size_t>(k)] = v != 0.0;
    }
  }
  auto& r = log->report;
  r.rows = r.samples = static_cast<long>(n);
  r.duration_s = n > 1 ? tp[n - 1] - tp[0] : 0.0;
  if (n > 1) {
    std::vector<double> dt(static_cast<size_t>(n - 1));
    for (py::ssize_t k = 1; k < n; ++k) dt[static_cast<size_t>(k - 1)] = tp[k] - tp[k - 1];
    r.median_dt_s = eval::quantile(dt, 0.5);
    r.rate_hz = r.median_dt_s > 0.0 ? 1.0 / r.median_dt_s : 0.0;
  }
  return ImuLog{std::move(log), "arrays"};
}

int first_week(const io::ImuLog& log) { return log.samples.empty() ? 0 : log.samples.front().t.week(); }

py::array_t<double> imu_times(const ImuLog& l) {
  const int week = first_week(*l.log);
  py::array_t<double> a(static_cast<py::ssize_t>(l.log->samples.size()));
  for (size_t k = 0; k < l.log->samples.size(); ++k) a.mutable_at(k) = seconds_of_week(l.log->samples[k].t, week);
  return a;
}

py::array_t<double> imu_vectors(const ImuLog& l, bool gyro) {
  const auto n = static_cast<py::ssize_t>(l.log->samples.size());
  py::array_t<double> a({n, py::ssize_t{3}});
  auto m = a.mutable_unchecked<2>();
  for (py::ssize_t k = 0; k < n; ++k) {
    const auto& s = l.log->samples[static_cast<size_t>(k)];
    const Eigen::Vector3d& v = gyro ? s.omega_ib_b : s.f_ib_b;
    for (int i = 0; i < 3; ++i) m(k, i) = v(i);
  }
  return a;
}

// The IMU format of read_imu: a preset name, a column map (dict), or None with a configuration's imu.format.
static io::ImuFormat imu_format_of(const py::object& format) {
  if (py::isinstance<py::str>(format)) {
    auto f = io::imu_format_preset(format.cast<std::string>());
    if (!f) raise(PyExc_ValueError, "format: " + f.error().message);
    return *f;
  }
  if (py::isinstance<py::dict>(format)) {
    // Read as the `imu.format` key of a run configuration: the same reader and messages (imu.format.<key>).
    auto problems = std::make_shared<io::YamlProblems>();
    problems->file = "format";
    io::ImuFormat f;
    {
      io::YamlMap m(YAML::Load(py_to_yaml(format, "imu.format")), "imu.format", problems, fs::current_path());
      io::read_imu_format(m, f);
      m.finish();
    }
    for (const auto& p : f.problems()) problems->messages.push_back("imu.format." + p);
    if (!problems->empty()) raise(PyExc_ValueError, problems->joined());
    return f;
  }
  std::string names;
  for (const auto& n : io::imu_format_preset_names()) names += (names.empty() ? "" : ", ") + n;
  raise(PyExc_ValueError, "format: a preset name (" + names + ") or a column map (dict) expected");
}

ImuLog read_imu(const py::object& source, const py::object& format) {
  std::string path;
  io::ImuFormat f;
  if (py::isinstance<Config>(source)) {
    const io::RunConfig& c = *source.cast<const Config&>().c;
    if (c.imu.file.empty()) raise(PyExc_ValueError, c.source_file + ": imu.file: not set");
    path = c.imu.file;
    f = format.is_none() ? c.imu.format : imu_format_of(format);
  } else {
    path = path_of(source);
    if (format.is_none()) {
      raise(PyExc_ValueError, "read_imu(" + path + "): format= is required with a file name (a preset name or a "
                              "column map; or pass a Config with imu.format)");
    }
    f = imu_format_of(format);
  }
  if (!fs::exists(path)) raise(PyExc_FileNotFoundError, path + ": no such file");
  Expected<io::ImuLog> log = [&] {
    py::gil_scoped_release nogil;
    return io::read_imu_csv(path, f);
  }();
  if (!log) raise(PyExc_ValueError, log.error().message);
  for (const auto& w : log->report.warnings) spdlog::warn("{}: {}", path, w);
  return ImuLog{std::make_shared<const io::ImuLog>(std::move(*log)), path};
}

py::dict imu_report(const ImuLog& l) {
  const auto& r = l.log->report;
  py::dict d("rows"_a = r.rows, "samples"_a = r.samples, "duplicates_dropped"_a = r.duplicates_dropped,
             "bad_rows"_a = r.bad_rows, "truncated_rows"_a = r.truncated_rows, "gaps"_a = r.gaps,
             "longest_gap_s"_a = r.longest_gap_s, "rate_hz"_a = r.rate_hz, "duration_s"_a = r.duration_s,
             "saturated_samples"_a = r.saturated_samples, "warnings"_a = r.warnings);
  return d;
}

}  // namespace pednav::python
