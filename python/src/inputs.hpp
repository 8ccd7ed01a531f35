// SPDX-License-Identifier: BSD-2-Clause
// The inputs of the Python module `pednav` (python/src/module.cpp, docs/python.md): Config (a validated run
// configuration) and ImuLog (IMU samples), made from files, dicts or numpy arrays with the CLI's checks and messages.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/time.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "python/src/convert.hpp"

namespace pednav::python {

namespace py = pybind11;

/// RTKLIB (RINEX reading and writing, LAMBDA) is called from one thread at a time: every call that reaches it holds this.
std::mutex& rtklib_mutex();

/// A file the caller names, read without the GIL: FileNotFoundError when it does not exist, ValueError with the
/// reader's message when `read(path)` (returning Expected<T>) fails.
template <class Read>
auto read_file_or_raise(const std::string& path, Read read) {
  if (!std::filesystem::exists(path)) raise(PyExc_FileNotFoundError, path + ": no such file");
  auto r = [&] {
    py::gil_scoped_release nogil;
    return read(path);
  }();
  if (!r) raise(PyExc_ValueError, r.error().message);
  return std::move(*r);
}

/// A validated run configuration (the YAML of `pednav run` / `pednav config-check`).
struct Config {
  std::shared_ptr<const io::RunConfig> c;
};

/// What `pednav config-check` reports for `c`: the run problems raise ValueError, missing input files
/// FileNotFoundError; each line "<source>: <problem>", as the CLI prints them.
void check_config(const io::RunConfig& c);
/// A file name argument: str or os.PathLike.
std::string path_of(const py::handle& obj);
Config config_from_yaml(const py::object& path_obj);
/// From a dict: the messages name the key path (the line numbers of the YAML made from the dict are dropped).
Config config_from_dict(const py::dict& d, const std::optional<std::string>& base_dir);
py::object config_to_dict(const Config& c);

/// IMU samples in GPS time, body frame, SI units.
struct ImuLog {
  std::shared_ptr<const io::ImuLog> log;
  std::string source;  ///< the file it was read from, or "arrays"
};

/// Seconds of a time since the start of GPS week `week`.
double seconds_of_week(GpsTime t, int week);
int first_week(const io::ImuLog& log);
ImuLog imu_from_arrays(const py::handle& t_obj, const py::handle& gyro_obj, const py::handle& accel_obj,
                       const py::object& stance_obj, int gps_week);
py::array_t<double> imu_times(const ImuLog& l);
py::array_t<double> imu_vectors(const ImuLog& l, bool gyro);
/// read_imu(source, format): a file (preset name or column map) or a Config with imu.file and imu.format.
ImuLog read_imu(const py::object& source, const py::object& format);
py::dict imu_report(const ImuLog& l);

}  // namespace pednav::python
