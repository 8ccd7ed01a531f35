// SPDX-License-Identifier: BSD-2-Clause
// The Python module `pednav` (docs/python.md): the use cases of the command line in memory, over the same pipeline
// functions (pipeline/*_command.hpp) — Config, ImuLog, read_imu, run, gnss, simulate, compare, calibrate,
// detect_stance. Numbers in, numpy arrays out; errors are Python exceptions with the CLI's one-line messages.
//
// Threads: the GIL is released while the engine and the readers run. RTKLIB (RINEX reading and writing, LAMBDA) is
// called from one thread at a time (STYLE.md): every call that reaches it holds rtklib_mutex().
// Ctrl-C and progress: fusion::EngineInputs::cancel is called every kCancelCheckSamples IMU samples; at most every
// kHookPeriod it takes the GIL, runs PyErr_CheckSignals and the progress callback, and stops the engine on an
// exception (KeyboardInterrupt), which is raised once the engine has returned.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <fmt/format.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "io/hmm_model_io.hpp"
#include "io/imu_csv.hpp"
#include "io/scenario_config.hpp"
#include "io/trajectory_io.hpp"
#include "io/yaml_schema.hpp"
#include "ins/zupt_detector.hpp"
#include "pipeline/calibrate_command.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/gnss_command.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/self_calibration.hpp"
#include "pipeline/simulate_command.hpp"
#include "python/src/convert.hpp"
#include "python/src/inputs.hpp"

namespace pednav::python {
namespace {

using namespace pybind11::literals;
namespace fs = std::filesystem;

constexpr auto kHookPeriod = std::chrono::milliseconds(50);  ///< GIL taken by the engine hook at most this often

// ---------------------------------------------------------------------------------------------------------------
// Progress, Ctrl-C

/// The engine hook of one run: progress callback and signal check with the GIL, an exception kept for after.
class EngineHook {
 public:
  EngineHook(py::object progress, GpsTime t0, GpsTime t1) : progress_(std::move(progress)), t0_(t0), t1_(t1) {}

  std::function<bool(GpsTime)> function() {
    return [this](GpsTime t) { return check(t); };
  }
  /// With the GIL: re-raise what stopped the engine (KeyboardInterrupt, the callback's exception).
  void rethrow_if_stopped() {
    if (error_) {
      error_->restore();
      error_.reset();
      throw py::error_already_set();
    }
  }
  void finish() {
    if (!progress_.is_none()) call(1.0);
  }

 private:
  bool check(GpsTime t) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < kHookPeriod) return false;
    last_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      error_.emplace();
      return true;
    }
    if (progress_.is_none()) return false;
    const double span = t1_ - t0_;
    const double f = span > 0.0 ? std::clamp((t - t0_) / span, 0.0, 1.0) : 1.0;
    fraction_ = std::max(fraction_, f);  // the heading pass re-runs the start: the fraction never goes back
    try {
      call(fraction_);
    } catch (py::error_already_set& e) {
      e.restore();
      error_.emplace();
      return true;
    }
    return false;
  }
  void call(double f) { progress_(f); }

  py::object progress_;
  GpsTime t0_, t1_;
  double fraction_ = 0.0;
  std::chrono::steady_clock::time_point last_{};
  std::optional<py::error_already_set> error_;
};

/// The progress argument as a callable: None/False -> None, True -> a tqdm bar when tqdm is importable (else None),
/// a callable -> itself (called with the fraction done, 0..1).
struct Progress {
  py::object callback = py::none();
  py::object bar = py::none();
  explicit Progress(const py::object& arg, const std::string& label) {
    if (arg.is_none() || (py::isinstance<py::bool_>(arg) && !arg.cast<bool>())) return;
    if (py::isinstance<py::bool_>(arg)) {
      try {
        bar = py::module_::import("tqdm").attr("tqdm")("total"_a = 100, "desc"_a = label, "unit"_a = "%");
      } catch (py::error_already_set&) {
        return;  // no tqdm: no bar
      }
      py::object b = bar;
      auto last = std::make_shared<int>(0);
      callback = py::cpp_function([b, last](double f) {
        const int n = static_cast<int>(f * 100.0);
        if (n > *last) b.attr("update")(n - *last);
        *last = std::max(*last, n);
      });
      return;
    }
    if (!PyCallable_Check(arg.ptr())) raise(PyExc_ValueError, "progress: None, a bool or a callable expected");
    callback = arg;
  }
  void close() {
    if (!bar.is_none()) bar.attr("close")();
  }
};

// ---------------------------------------------------------------------------------------------------------------
// run

/// A `pednav run` result in memory.
struct Result {
  std::shared_ptr<pipeline::RunOutputs> out;
  std::string source;  ///< the configuration file
};

py::dict residual_columns(const std::vector<fusion::GnssRowRecord>& rows) {
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::array_t<int64_t> week(n);
  py::array_t<double> tow(n), innovation(n), sigma(n), w(n), mdb(n), w_final(n);
  py::array_t<bool> rejected(n);
  py::list sat, type;
  for (py::ssize_t k = 0; k < n; ++k) {
    const auto& r = rows[static_cast<size_t>(k)];
    week.mutable_at(k) = r.t.week();
    tow.mutable_at(k) = r.t.tow_s();
    sat.append(r.sat.to_string());
    type.append(r.doppler ? "doppler" : "code");
    innovation.mutable_at(k) = r.innovation;
    sigma.mutable_at(k) = r.sigma;
    w.mutable_at(k) = r.w;
    mdb.mutable_at(k) = r.mdb;
    rejected.mutable_at(k) = r.rejected;
    w_final.mutable_at(k) = r.w_final;
  }
  py::module_ np = py::module_::import("numpy");
  return py::dict("gps_week"_a = week, "gps_tow_s"_a = tow, "sat"_a = np.attr("array")(sat, "dtype"_a = "U3"),
                  "type"_a = np.attr("array")(type, "dtype"_a = "U7"), "innovation"_a = innovation, "sigma"_a = sigma,
                  "w"_a = w, "mdb"_a = mdb, "rejected"_a = rejected, "w_final"_a = w_final);
}

Result run(const Config& config, const std::optional<ImuLog>& imu, const std::optional<std::string>& mode,
           const py::object& progress_arg) {
  io::RunConfig c = *config.c;
  if (mode) {
    if (*mode != "tc" && *mode != "ins") raise(PyExc_ValueError, "mode: " + *mode + " (tc or ins expected)");
    c.mode = *mode;
  }
  if (auto as_run = pipeline::run_config_for_mode(c); !as_run) {
    raise(PyExc_ValueError, as_run.error().message);
  } else {
    c = *as_run;
  }
  if (!imu) {
    if (auto missing = io::missing_input_files(c); !missing.empty()) {
      std::string all;
      for (const auto& m : missing) all += (all.empty() ? "" : "; ") + m;
      raise(PyExc_FileNotFoundError, c.source_file + ": " + all);
    }
  }
  // The IMU log is read here, outside the RTKLIB lock (the reader pipeline::load_run_inputs uses, after the same
  // configuration check), so that only the RINEX reading of two concurrent runs is serialized.
  const io::ImuLog* given = imu ? imu->log.get() : nullptr;
  io::ImuLog read_log;
  if (!given && pipeline::run_config_problems(c).empty()) {
    Expected<io::ImuLog> l = [&] {
      py::gil_scoped_release nogil;
      return io::read_imu_csv(c.imu.file, c.imu.format);
    }();
    if (!l) raise(PyExc_ValueError, l.error().message);
    for (const auto& w : l->report.warnings) spdlog::warn("{}: {}", c.imu.file, w);
    read_log = std::move(*l);
    given = &read_log;
  }
  Expected<pipeline::RunInputs> inputs = [&] {
    py::gil_scoped_release nogil;
    std::unique_lock<std::mutex> lock(rtklib_mutex(), std::defer_lock);
    if (c.mode == "tc") lock.lock();  // RINEX through RTKLIB
    return pipeline::load_run_inputs(c, given);
  }();
  if (!inputs) raise(PyExc_ValueError, inputs.error().message);
  const auto& samples = inputs->imu.samples;
  Progress progress(progress_arg, "pednav.run");
  EngineHook hook(progress.callback, samples.empty() ? GpsTime{} : samples.front().t,
                  samples.empty() ? GpsTime{} : samples.back().t);
  Expected<pipeline::RunOutputs> out = [&] {
    py::gil_scoped_release nogil;
    std::unique_lock<std::mutex> lock(rtklib_mutex(), std::defer_lock);
    if (inputs->options.carrier) lock.lock();  // LAMBDA through RTKLIB
    return pipeline::compute_run(c, *inputs, hook.function());
  }();
  if (out) {
    try {
      hook.finish();  // the callback sees 1.0 (the bar reaches its end) before the bar closes
    } catch (py::error_already_set&) {
      progress.close();
      throw;
    }
  }
  progress.close();
  hook.rethrow_if_stopped();
  if (!out) raise(PyExc_RuntimeError, out.error().message);
  return Result{std::make_shared<pipeline::RunOutputs>(std::move(*out)), c.source_file};
}

py::object optional_json_text(const std::string& text) {
  if (text.empty()) return py::none();
  return py::module_::import("json").attr("loads")(text);
}

// ---------------------------------------------------------------------------------------------------------------
// gnss, simulate, compare, calibrate, detect_stance

/// A folder for outputs: the caller's, or a new temporary one (removed by the caller when `temporary`).
struct OutDir {
  std::string path;
  bool temporary = false;
};

OutDir out_dir_of(const std::optional<std::string>& out_dir, const std::string& prefix) {
  if (out_dir) return {*out_dir, false};
  py::object tempfile = py::module_::import("tempfile");
  return {tempfile.attr("mkdtemp")("prefix"_a = prefix).cast<std::string>(), true};
}

py::dict read_json_file(const std::string& path) {
  py::object f = py::module_::import("builtins").attr("open")(path, "r", "encoding"_a = "utf-8");
  py::object j = py::module_::import("json").attr("load")(f);
  f.attr("close")();
  return j;
}

py::dict gnss_solution(const Config& config, const std::optional<std::string>& out_dir) {
  const io::RunConfig& c = *config.c;
  if (auto missing = io::missing_input_files(c); !missing.empty()) {
    std::string all;
    for (const auto& m : missing) all += (all.empty() ? "" : "; ") + m;
    raise(PyExc_FileNotFoundError, c.source_file + ": " + all);
  }
  const OutDir dir = out_dir_of(out_dir, "pednav_gnss_");
  Expected<pipeline::GnssRunSummary> s = [&] {
    py::gil_scoped_release nogil;
    std::lock_guard<std::mutex> lock(rtklib_mutex());
    return pipeline::run_gnss_command(c, dir.path);
  }();
  auto cleanup = [&] {
    if (dir.temporary) fs::remove_all(dir.path);
  };
  if (!s) {
    cleanup();
    raise(PyExc_RuntimeError, s.error().message);
  }
  const fs::path p(dir.path);
  py::dict d("solution"_a = read_csv_columns((p / "gnss.csv").string()),
             "summary"_a = read_json_file((p / "summary.json").string()));
  if (fs::exists(p / "evaluation.json")) d["evaluation"] = read_json_file((p / "evaluation.json").string());
  d["out_dir"] = dir.temporary ? py::object(py::none()) : py::object(py::str(dir.path));
  cleanup();
  return d;
}

py::dict simulate(const py::object& scenario, const std::optional<std::string>& out_dir) {
  const io::ScenarioFile sc =
      read_file_or_raise(path_of(scenario), [](const std::string& p) { return io::load_scenario(p); });
  const OutDir dir = out_dir_of(out_dir, "pednav_simulate_");
  Expected<pipeline::SimulateSummary> s = [&] {
    py::gil_scoped_release nogil;
    std::lock_guard<std::mutex> lock(rtklib_mutex());  // RINEX writing through RTKLIB
    return pipeline::run_simulate_command(sc, dir.path);
  }();
  if (!s) raise(PyExc_RuntimeError, s.error().message);
  const fs::path p(dir.path);
  py::dict files;
  const std::pair<const char*, const char*> written[] = {
      {"truth", "truth.csv"},   {"imu", "imu.csv"},       {"rover_obs", "rover.obs"},
      {"base_obs", "base.obs"}, {"nav", "nav.rnx"},       {"config", "config.yaml"},
      {"config_datasheet", "config_datasheet.yaml"},      {"blunders", "blunders.csv"},
      {"slips", "slips.csv"}};
  for (const auto& [key, name] : written) {
    if (fs::exists(p / name)) files[key] = (p / name).string();
  }
  Config cfg = config_from_yaml(py::str((p / "config.yaml").string()));
  ImuLog imu = read_imu(py::cast(cfg), py::none());
  py::dict summary("duration_s"_a = s->duration_s, "distance_m"_a = s->distance_m, "strides"_a = s->strides,
                   "imu_samples"_a = s->imu_samples, "truth_rows"_a = s->truth_rows, "rover_epochs"_a = s->rover_epochs,
                   "base_epochs"_a = s->base_epochs, "blunder_events"_a = s->blunder_events,
                   "carrier_phase"_a = s->carrier_phase, "saturated_samples"_a = s->saturated_samples,
                   "max_gyro_radps"_a = s->max_gyro_radps, "wall_s"_a = s->wall_s);
  return py::dict("out_dir"_a = dir.path, "truth"_a = read_csv_columns((p / "truth.csv").string()), "imu"_a = imu,
                  "config"_a = cfg, "files"_a = files, "summary"_a = summary);
}

eval::Align align_of(const std::string& a) {
  if (a == "none") return eval::Align::kNone;
  if (a == "start") return eval::Align::kStart;
  if (a == "start-pyshoe") return eval::Align::kStartPyshoe;
  if (a == "best-fit-2d") return eval::Align::kBestFit2d;
  if (a == "best-fit-3d") return eval::Align::kBestFit3d;
  raise(PyExc_ValueError, "align: " + a + " (none, start, start-pyshoe, best-fit-2d or best-fit-3d expected)");
}

// A trajectory argument of compare: a file name, or a Result (its forward solution, or `which`).
io::TrajectoryFile trajectory_of(const py::object& obj, const std::string& what, const std::string& format,
                                 const std::string& which, std::string& name) {
  if (py::isinstance<Result>(obj)) {
    const Result& r = obj.cast<const Result&>();
    if (which != "forward" && which != "smoothed") raise(PyExc_ValueError, "which: forward or smoothed expected");
    if (which == "smoothed" && r.out->smoothed_rows.empty()) raise(PyExc_ValueError, "which: the run has no smoothed solution");
    io::TrajectoryFile tf;
    tf.format = "csv";
    // As pipeline::evaluate_rows takes a run's rows (σ E, N, U from the NED covariance).
    for (const auto& row : which == "forward" ? r.out->rows : r.out->smoothed_rows) {
      const Eigen::Vector3d sd_enu(std::sqrt(row.cov_p_n(1, 1)), std::sqrt(row.cov_p_n(0, 0)),
                                   std::sqrt(row.cov_p_n(2, 2)));
      tf.trajectory.points.push_back({row.time, row.p_e, sd_enu});
    }
    name = which == "forward" ? "solution.csv" : "smoothed.csv";
    return tf;
  }
  name = path_of(obj);
  if (!fs::exists(name)) raise(PyExc_FileNotFoundError, name + ": no such file");
  io::TrajectoryReadOptions ro;
  auto f = io::parse_trajectory_format(format);
  if (!f) raise(PyExc_ValueError, what + "_format: " + f.error().message);
  ro.format = *f;
  Expected<io::TrajectoryFile> t = [&] {
    py::gil_scoped_release nogil;
    return io::read_trajectory(name, ro);
  }();
  if (!t) raise(PyExc_ValueError, t.error().message);
  return std::move(*t);
}

py::dict compare(const py::object& solution, const py::object& reference, const std::string& align, bool loop,
                 double tolerance_s, double segment_s, const std::string& solution_format,
                 const std::string& reference_format, const std::string& which) {
  pipeline::CompareArgs args;
  args.compare.align = align_of(align);
  args.compare.loop = loop;
  args.compare.time_tolerance_s = tolerance_s;
  args.segment_s = segment_s;
  if (!(segment_s > 0.0)) raise(PyExc_ValueError, "segment_s: must be positive");
  const io::TrajectoryFile sol = trajectory_of(solution, "solution", solution_format, which, args.solution);
  const io::TrajectoryFile ref = trajectory_of(reference, "reference", reference_format, which, args.reference);
  Expected<eval::Evaluation> ev = [&] {
    py::gil_scoped_release nogil;
    return eval::compare(sol.trajectory, ref.trajectory, args.compare);
  }();
  if (!ev) raise(PyExc_ValueError, args.solution + " vs " + args.reference + ": " + ev.error().message);
  const auto n = static_cast<py::ssize_t>(ev->errors.size());
  py::array_t<int64_t> week(n);
  py::array_t<double> tow(n), de(n), dn(n), du(n), h(n), sd_e(n), sd_n(n), sd_u(n);
  for (py::ssize_t k = 0; k < n; ++k) {
    const eval::EpochError& e = ev->errors[static_cast<size_t>(k)];
    week.mutable_at(k) = e.t.week();
    tow.mutable_at(k) = e.t.tow_s();
    de.mutable_at(k) = e.d_enu.x();
    dn.mutable_at(k) = e.d_enu.y();
    du.mutable_at(k) = e.d_enu.z();
    h.mutable_at(k) = e.horizontal_m;
    sd_e.mutable_at(k) = e.sd_enu_m.x();
    sd_n.mutable_at(k) = e.sd_enu_m.y();
    sd_u.mutable_at(k) = e.sd_enu_m.z();
  }
  py::dict errors("gps_week"_a = week, "gps_tow_s"_a = tow, "de_m"_a = de, "dn_m"_a = dn, "du_m"_a = du,
                  "horizontal_m"_a = h, "sd_e_m"_a = sd_e, "sd_n_m"_a = sd_n, "sd_u_m"_a = sd_u);
  py::object evaluation = py::module_::import("json").attr("loads")(pipeline::evaluation_json(*ev, args, sol, ref));
  return py::dict("evaluation"_a = evaluation, "errors"_a = errors,
                  "markdown"_a = pipeline::evaluation_markdown(*ev, args));
}

io::RunConfig config_or_default(const std::optional<Config>& config) {
  return config ? *config->c : io::RunConfig{};
}

py::dict calibrate(const ImuLog& imu, const std::optional<Config>& config) {
  io::RunConfig c = config_or_default(config);
  c.imu.spec_auto = true;
  c.zupt.shoe_threshold_auto = true;
  std::optional<pipeline::SelfCalibration> s;
  {
    py::gil_scoped_release nogil;
    s = pipeline::resolve_self_calibration(c, *imu.log);
  }
  if (!s) raise(PyExc_RuntimeError, "calibrate: no calibration (internal)");
  nlohmann::ordered_json j = pipeline::self_calibration_json(*s);
  j["imu_file"] = imu.source;
  return py::dict("calibration"_a = json_to_py(j), "yaml"_a = pipeline::calibration_yaml(*s, imu.source));
}

py::dict detect_stance(const ImuLog& imu, const std::optional<std::string>& detector, const std::optional<Config>& config) {
  io::RunConfig c = config_or_default(config);
  if (detector) c.zupt.detector = *detector;
  pipeline::resolve_self_calibration(c, *imu.log);  // zupt.shoe_threshold: auto
  const ins::ZuptDetectorOptions opt = io::zupt_detector_options(c.zupt);
  if (auto p = opt.problems(); !p.empty()) raise(PyExc_ValueError, p.front());
  const auto& samples = imu.log->samples;
  if (auto p = ins::stance_label_problem(opt, &imu.log->stance, samples.size()); !p.empty()) {
    raise(PyExc_ValueError, p);
  }
  std::vector<ins::ZuptDecision> d;
  {
    py::gil_scoped_release nogil;
    d = opt.detector == "hmm" ? ins::detect_gait_hmm(samples, opt).decisions
                              : ins::detect_stance(samples, opt, &imu.log->stance);
  }
  const auto n = static_cast<py::ssize_t>(d.size());
  py::array_t<bool> stance(n);
  py::array_t<double> statistic(n);
  py::array_t<int8_t> gait(n);
  for (py::ssize_t k = 0; k < n; ++k) {
    stance.mutable_at(k) = d[static_cast<size_t>(k)].stance;
    statistic.mutable_at(k) = d[static_cast<size_t>(k)].statistic;
    gait.mutable_at(k) = static_cast<int8_t>(d[static_cast<size_t>(k)].gait_state);
  }
  return py::dict("t_s"_a = imu_times(imu), "stance"_a = stance, "statistic"_a = statistic, "gait_state"_a = gait,
                  "detector"_a = opt.detector, "steps"_a = static_cast<long>(ins::stance_phases(d).size()));
}

void set_log_level(const std::string& level) {
  const auto l = spdlog::level::from_str(level);
  if (l == spdlog::level::off && level != "off") {
    raise(PyExc_ValueError, "level: " + level + " (trace, debug, info, warning, error, critical or off expected)");
  }
  spdlog::set_level(l);
}

}  // namespace
}  // namespace pednav::python

PYBIND11_MODULE(pednav, m) {
  using namespace pednav;
  using namespace pednav::python;
  using namespace pybind11::literals;
  m.doc() = "pednav: foot-mounted IMU + GNSS navigation (the pednav engine in memory; docs/python.md)";
  m.attr("__version__") = PEDNAV_VERSION;
  // The engine's log lines (the CLI's warnings) on stderr; warnings and errors only unless set_log_level("info").
  auto logger = spdlog::stderr_logger_mt("pednav_python");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::warn);
  m.def("set_log_level", &set_log_level, "level"_a, "Level of the engine's log lines on stderr (default warning).");

  py::class_<Config>(m, "Config", "A validated run configuration (the YAML of `pednav run` / `pednav config-check`).")
      .def_static("from_yaml", &config_from_yaml, "path"_a)
      .def_static("from_dict", &config_from_dict, "d"_a, "base_dir"_a = py::none())
      .def("to_dict", &config_to_dict)
      .def("to_yaml", [](const Config& c) { return io::to_yaml(*c.c); })
      .def_property_readonly("mode", [](const Config& c) { return c.c->mode; })
      .def_property_readonly("source_file", [](const Config& c) { return c.c->source_file; })
      .def("__repr__", [](const Config& c) { return "<pednav.Config " + c.c->source_file + " mode " + c.c->mode + ">"; });

  py::class_<ImuLog>(m, "ImuLog", "IMU samples in GPS time, body frame, SI units.")
      .def(py::init([](const py::object& t, const py::object& g, const py::object& a, const py::object& stance, int week) {
             return imu_from_arrays(t, g, a, stance, week);
           }),
           "t_s"_a, "gyro_radps"_a, "accel_mps2"_a, "stance_label"_a = py::none(), "gps_week"_a = 0)
      .def_property_readonly("t_s", &imu_times)
      .def_property_readonly("gps_week", [](const ImuLog& l) { return first_week(*l.log); })
      .def_property_readonly("gyro_radps", [](const ImuLog& l) { return imu_vectors(l, true); })
      .def_property_readonly("accel_mps2", [](const ImuLog& l) { return imu_vectors(l, false); })
      .def_property_readonly("stance_label",
                             [](const ImuLog& l) -> py::object {
                               if (l.log->stance.empty()) return py::none();
                               py::array_t<uint8_t> a(static_cast<py::ssize_t>(l.log->stance.size()));
                               std::copy(l.log->stance.begin(), l.log->stance.end(), a.mutable_data());
                               return a;
                             })
      .def_property_readonly("report", &imu_report)
      .def_property_readonly("source", [](const ImuLog& l) { return l.source; })
      .def("__len__", [](const ImuLog& l) { return l.log->samples.size(); })
      .def("__repr__", [](const ImuLog& l) {
        return fmt::format("<pednav.ImuLog {} samples from {}>", l.log->samples.size(), l.source);
      });

  py::class_<Result>(m, "Result", "What `pednav run` computes, in memory.")
      .def_property_readonly("forward", [](const Result& r) { return solution_columns(r.out->rows); })
      .def_property_readonly("smoothed", [](const Result& r) -> py::object {
        if (r.out->smoothed_rows.empty()) return py::none();
        return solution_columns(r.out->smoothed_rows);
      })
      .def_property_readonly("summary", [](const Result& r) { return json_to_py(r.out->summary); })
      .def_property_readonly("residuals", [](const Result& r) -> py::object {
        if (!r.out->tightly_coupled) return py::none();
        return residual_columns(r.out->result.gnss_rows);
      })
      .def_property_readonly("evaluation", [](const Result& r) { return optional_json_text(r.out->evaluation_json); })
      .def_property_readonly("evaluation_smoothed",
                             [](const Result& r) { return optional_json_text(r.out->evaluation_smoothed_json); })
      .def_property_readonly("config", [](const Result& r) {
        return Config{std::make_shared<const io::RunConfig>(r.out->config)};
      })
      .def("write", [](const Result& r, const std::string& out_dir) {
        Expected<void> ok = [&] {
          py::gil_scoped_release nogil;
          return pipeline::write_run_outputs(r.out->config, *r.out, out_dir);
        }();
        if (!ok) raise(PyExc_OSError, ok.error().message);
      }, "out_dir"_a)
      .def("to_pandas", [](const Result& r, const std::string& which) {
        py::object pd;
        try {
          pd = py::module_::import("pandas");
        } catch (py::error_already_set&) {
          raise(PyExc_ImportError, "to_pandas needs pandas (the columns are numpy arrays in Result.forward)");
        }
        if (which != "forward" && which != "smoothed") raise(PyExc_ValueError, "which: forward or smoothed expected");
        const auto& rows = which == "forward" ? r.out->rows : r.out->smoothed_rows;
        return pd.attr("DataFrame")(solution_columns(rows));
      }, "which"_a = "forward")
      .def("__repr__", [](const Result& r) {
        return fmt::format("<pednav.Result {} forward, {} smoothed epochs of {}>", r.out->rows.size(),
                           r.out->smoothed_rows.size(), r.source);
      });

  m.def("read_imu", &read_imu, "source"_a, "format"_a = py::none(),
        "Read an IMU log: a file name with format= (preset name or column map), or a Config (imu.file, imu.format).");
  m.def("run", &run, "config"_a, "imu"_a = py::none(), "mode"_a = py::none(), "progress"_a = py::none(),
        "`pednav run` in memory: forward (+ smoothed) solution, summary, residuals.");
  m.def("gnss", &gnss_solution, "config"_a, "out_dir"_a = py::none(),
        "`pednav gnss`: GNSS-only solution (written into out_dir, or a temporary folder removed afterwards).");
  m.def("simulate", &simulate, "scenario"_a, "out_dir"_a = py::none(),
        "`pednav simulate`: truth, IMU and RINEX files of a scenario in out_dir (default: a new temporary folder).");
  m.def("compare", &compare, "solution"_a, "reference"_a, "align"_a = "none", "loop"_a = false,
        "tolerance_s"_a = 0.05, "segment_s"_a = 120.0, "solution_format"_a = "auto", "reference_format"_a = "auto",
        "which"_a = "forward",
        "`pednav compare`: the evaluation dict and the per-epoch errors (a Result: its forward or smoothed solution).");
  m.def("calibrate", &calibrate, "imu"_a, "config"_a = py::none(),
        "`pednav calibrate`: what the log says about itself (imu.spec: auto, zupt.shoe_threshold: auto).");
  m.def("detect_stance", &detect_stance, "imu"_a, "detector"_a = py::none(), "config"_a = py::none(),
        "`pednav zupt`: the stance decision per IMU sample.");
}
