// SPDX-License-Identifier: BSD-2-Clause
#include "pipeline/zupt_command.hpp"

#include "pipeline/self_calibration.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "io/imu_csv.hpp"
#include "io/plot.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

Expected<ImuLog> read_log(const RunConfig& c) {
  if (c.imu.file.empty()) return make_error(c.source_file + ": imu.file: required for zero-velocity detection");
  if (!c.imu.has_format) return make_error(c.source_file + ": imu.format: required (a preset name or a column map)");
  auto imu = read_imu_csv(c.imu.file, c.imu.format);
  if (!imu) return imu.error();
  for (const auto& w : imu->report.warnings) spdlog::warn("{}: {}", c.imu.file, w);
  if (imu->samples.size() < 10) return make_error(c.imu.file + ": fewer than 10 IMU samples");
  return std::move(*imu);
}

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json j = nlohmann::json::array();
  for (int i = 0; i < m.rows(); ++i) {
    std::vector<double> row(static_cast<std::size_t>(m.cols()));
    for (int k = 0; k < m.cols(); ++k) row[static_cast<std::size_t>(k)] = m(i, k);
    j.push_back(row);
  }
  return j;
}

}  // namespace

Expected<ZuptCommandSummary> run_zupt_command(const RunConfig& c, const std::string& out_dir) {
  const auto wall0 = std::chrono::steady_clock::now();
  auto log = read_log(c);
  if (!log) return log.error();
  const std::vector<ins::ImuSample>* samples = &log->samples;
  RunConfig resolved = c;  // `zupt.shoe_threshold: auto` from the log (pipeline/self_calibration)
  resolve_self_calibration(resolved, *log);
  const ins::ZuptDetectorOptions opt = zupt_detector_options(resolved.zupt);
  if (auto p = opt.problems(); !p.empty()) return make_error(c.source_file + ": " + p.front());
  if (auto p = ins::stance_label_problem(opt, &log->stance, samples->size()); !p.empty())
    return make_error(c.source_file + ": " + p);
  ZuptCommandSummary sum;
  sum.detector = opt.detector;
  std::vector<ins::ZuptDecision> d;
  std::vector<int> grade;
  nlohmann::json j;
  if (opt.detector == "hmm") {
    ins::HmmDetection h = ins::detect_gait_hmm(*samples, opt);
    d = std::move(h.decisions);
    grade = h.observations.grade;
    sum.hmm_observations = static_cast<long>(h.observations.obs.size());
    sum.hmm_iterations = h.training.iterations;
    sum.hmm_model = h.model;
    j["hmm"] = {{"observations", sum.hmm_observations},
                {"axis_sign", h.sign},
                {"trained_on_log", opt.hmm_train_on_log},
                {"iterations", h.training.iterations},
                {"converged", h.training.converged},
                {"log_likelihood", h.training.log_likelihood},
                {"A", matrix_json(h.model.A)},
                {"B", matrix_json(h.model.B)},
                {"decoder", opt.hmm_decoder}};
  } else {
    d = ins::detect_stance(*samples, opt, &log->stance);
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create the output folder: " + ec.message());
  const std::filesystem::path out(out_dir);
  {
    AtomicFile f((out / "zupt.csv").string());
    if (!f.ok()) return make_error((out / "zupt.csv").string() + ": cannot write");
    auto& os = f.stream();
    os << "gps_week,gps_tow_s,stance,statistic,hmm_state,hmm_grade\n";
    for (std::size_t k = 0; k < d.size(); ++k) {
      const GpsTime& t = (*samples)[k].t;
      os << fmt::format("{},{:.6f},{},{:.6g},{},{}\n", t.week(), t.tow_s(), d[k].stance ? 1 : 0, d[k].statistic,
                        d[k].gait_state >= 0 ? std::string(1, ins::gait_state_letter(d[k].gait_state)) : "",
                        grade.empty() ? std::string() : std::to_string(grade[k] + 1));
    }
    if (auto ok = f.commit(); !ok) return ok.error();
  }
  sum.samples = static_cast<long>(d.size());
  for (std::size_t k = 0; k < d.size(); ++k) {
    sum.stance_samples += d[k].stance;
    sum.stance_intervals += d[k].stance && (k == 0 || !d[k - 1].stance);
  }
  sum.steps = static_cast<long>(ins::stance_phases(d).size());
  if (!log->stance.empty()) {
    long tp = 0, fp = 0, fn = 0;
    for (std::size_t k = 0; k < d.size(); ++k) {
      const bool label = log->stance[k] != 0;
      tp += d[k].stance && label;
      fp += d[k].stance && !label;
      fn += !d[k].stance && label;
    }
    sum.label_stance_samples = tp + fn;
    sum.label_precision = tp + fp > 0 ? static_cast<double>(tp) / static_cast<double>(tp + fp) : 0.0;
    sum.label_recall = tp + fn > 0 ? static_cast<double>(tp) / static_cast<double>(tp + fn) : 0.0;
    j["log_labels"] = {{"stance_samples", sum.label_stance_samples},
                       {"precision", sum.label_precision},
                       {"recall", sum.label_recall}};
  }
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  j["detector"] = sum.detector;
  j["imu_file"] = c.imu.file;
  j["samples"] = sum.samples;
  j["stance_samples"] = sum.stance_samples;
  j["stance_intervals"] = sum.stance_intervals;
  j["steps"] = sum.steps;
  j["wall_s"] = sum.wall_s;
  // Detections plot (io/plot, gnuplot): stance flag and the statistic scaled to its largest magnitude (HMM: the
  // smoothed signed axis rate; also the decoded state / 3), at most ~20000 points. A missing gnuplot is a warning.
  {
    PlotSpec ps;
    ps.title = "zero-velocity detector " + sum.detector + ": " + std::to_string(sum.steps) + " steps, " +
               std::to_string(sum.stance_intervals) + " stance intervals";
    ps.x_label = "GPS time of week [s]";
    ps.y_label = "stance (0/1), statistic / max|statistic|";
    double smax = 0.0;
    for (const auto& x : d) smax = std::max(smax, std::abs(x.statistic));
    const std::size_t step = std::max<std::size_t>(1, d.size() / 20000);
    PlotSeries st{"stance", PlotStyle::kSteps, {}, {}, {}, {}, "#1b9e77", 1.5};
    PlotSeries stat{"statistic (scaled)", PlotStyle::kLines, {}, {}, {}, {}, "#7570b3", 1.0};
    PlotSeries gait{"HMM state / 3 (A 0, B 1/3, C 2/3, D 1)", PlotStyle::kSteps, {}, {}, {}, {}, "#d95f02", 1.0};
    for (std::size_t k = 0; k < d.size(); k += step) {
      const double t = (*samples)[k].t.tow_s();
      st.x.push_back(t);
      st.y.push_back(d[k].stance ? 1.0 : 0.0);
      stat.x.push_back(t);
      stat.y.push_back(smax > 0 ? d[k].statistic / smax : 0.0);
      if (d[k].gait_state >= 0) {
        gait.x.push_back(t);
        gait.y.push_back(d[k].gait_state / 3.0);
      }
    }
    ps.series = {stat, st};
    if (!gait.x.empty()) ps.series.push_back(gait);
    ps.width_px = 1200;
    if (auto ok = write_plot_svg((out / "zupt.svg").string(), ps); !ok) {
      spdlog::warn("zupt.svg not written: {}", ok.error().message);
    }
  }
  if (auto ok = write_file_atomic((out / "summary.json").string(), j.dump(2) + "\n"); !ok) return ok.error();
  return sum;
}

Expected<HmmModelFile> run_hmm_train_command(const std::vector<RunConfig>& configs, const std::string& out_path,
                                             int max_iterations) {
  if (configs.empty()) return make_error("hmm-train: no configuration given");
  const ZuptConfig& z0 = configs.front().zupt;
  HmmModelFile f;
  f.extraction = {z0.hmm_gyro_axis, z0.hmm_smooth_window_s, z0.hmm_grade_width_radps};
  std::vector<std::vector<int>> sequences;
  for (const auto& c : configs) {
    const ZuptConfig& z = c.zupt;
    if (z.hmm_gyro_axis != z0.hmm_gyro_axis || z.hmm_smooth_window_s != z0.hmm_smooth_window_s ||
        z.hmm_grade_width_radps != z0.hmm_grade_width_radps) {
      return make_error(c.source_file + ": zupt.hmm_gyro_axis/hmm_smooth_window_s/hmm_grade_width_deg_per_s differ from " +
                        configs.front().source_file + " (one model needs one observation definition)");
    }
    auto log = read_log(c);
    if (!log) return log.error();
    const std::vector<ins::ImuSample>* samples = &log->samples;
    const ins::ZuptDetectorOptions opt = zupt_detector_options(z);
    if (auto p = opt.hmm_observations.problems(); !p.empty()) return make_error(c.source_file + ": zupt." + p.front());
    sequences.push_back(ins::extract_gait_observations(*samples, opt.hmm_observations).symbols());
    f.training.logs.push_back(c.imu.file);
    spdlog::info("{}: {} IMU samples -> {} observations", c.imu.file, samples->size(), sequences.back().size());
  }
  ins::BaumWelchOptions bw;
  bw.max_iterations = max_iterations;
  const ins::HmmModel initial = z0.hmm_model ? *z0.hmm_model : ins::seed002_initial_model();
  const ins::BaumWelchResult r = ins::baum_welch(initial, sequences, bw);
  if (r.log_likelihood.empty() || !std::isfinite(r.log_likelihood.back())) {
    return make_error("hmm-train: the observations are impossible under the initial model (log-likelihood -inf)");
  }
  f.model = r.model;
  f.training.observations = r.observations;
  f.training.iterations = r.iterations;
  f.training.converged = r.converged;
  f.training.log_likelihood_initial = r.log_likelihood.front();
  f.training.log_likelihood_final = r.log_likelihood.back();
  const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
  }
  if (auto ok = write_file_atomic(out_path, hmm_model_yaml(f)); !ok) return ok.error();
  return f;
}

}  // namespace pednav::pipeline
