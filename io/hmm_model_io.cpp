// SPDX-License-Identifier: BSD-2-Clause
#include "io/hmm_model_io.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <sstream>

#include "core/geodesy.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {
namespace {

// Read a list of `rows` lists of `cols` numbers into m (row-major); problems through `map`.
template <typename M>
void read_matrix(YamlMap& map, const std::string& key, M& m) {
  const YAML::Node n = map.raw(key);
  const std::string what = "expected " + std::to_string(m.rows()) + " lists of " + std::to_string(m.cols()) + " numbers";
  if (!n.IsDefined() || n.IsNull()) {
    map.problem(key, "required key is missing");
    return;
  }
  if (!n.IsSequence() || static_cast<long>(n.size()) != m.rows()) {
    map.problem(key, what);
    return;
  }
  for (int i = 0; i < m.rows(); ++i) {
    const YAML::Node row = n[static_cast<std::size_t>(i)];
    if (!row.IsSequence() || static_cast<long>(row.size()) != m.cols()) {
      map.problem(key, what + " (row " + std::to_string(i + 1) + ")");
      return;
    }
    for (int j = 0; j < m.cols(); ++j) {
      try {
        m(i, j) = row[static_cast<std::size_t>(j)].as<double>();
      } catch (const YAML::Exception&) {
        map.problem(key, "row " + std::to_string(i + 1) + " entry " + std::to_string(j + 1) + " is not a number");
        return;
      }
    }
  }
}

}  // namespace

bool parse_gyro_axis(const std::string& text, int& axis, double& sign) {
  if (text.empty() || text.size() > 2) return false;
  sign = text.size() == 2 ? (text[0] == '-' ? -1.0 : (text[0] == '+' ? 1.0 : 0.0)) : 1.0;
  const char a = text.back();
  axis = a == 'x' ? 0 : a == 'y' ? 1 : a == 'z' ? 2 : -1;
  return sign != 0.0 && axis >= 0;
}

Expected<HmmModelFile> read_hmm_model(const std::string& path) {
  auto src = read_yaml_source(path, "HMM model file");
  if (!src) return src.error();
  YAML::Node root;
  try {
    root = YAML::Load(src->text);
  } catch (const YAML::Exception& e) {
    return make_error(path + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!root || root.IsNull()) return make_error(path + ": HMM model file is empty");
  auto problems = std::make_shared<YamlProblems>();
  problems->file = path;
  HmmModelFile f;
  {
    YamlMap top(root, "", problems, src->base_dir);
    std::vector<std::string> states;
    top.strings("states", states);
    if (top.has("states") && states != std::vector<std::string>{"push_off", "swing", "heel_strike", "stance"}) {
      top.problem("states", "expected [push_off, swing, heel_strike, stance] (seed 002 states A, B, C, D)");
    }
    read_matrix(top, "A", f.model.A);
    read_matrix(top, "B", f.model.B);
    std::vector<double> pi;
    top.numbers("pi", pi, true);
    if (pi.size() == 4) {
      f.model.pi = Eigen::Vector4d(pi[0], pi[1], pi[2], pi[3]);
    } else if (top.has("pi")) {
      top.problem("pi", "expected 4 numbers");
    }
    {
      YamlMap x = top.map("extraction", true);
      x.text("gyro_axis", f.extraction.gyro_axis, true);
      int axis = 0;
      double sign = 1.0;
      if (!parse_gyro_axis(f.extraction.gyro_axis, axis, sign)) {
        x.problem("gyro_axis", "expected x, y, z, -x, -y or -z");
      }
      x.number("smooth_window_s", f.extraction.smooth_window_s, true, 0.0, 5.0);
      double w = 0.0;
      x.number("grade_width_deg_per_s", w, true, 1e-3, 5000.0);
      f.extraction.grade_width_radps = w * kDegToRad;
    }
    {
      YamlMap t = top.map("training");
      t.strings("logs", f.training.logs);
      double obs = 0;
      t.number("observations", obs, false, 0.0, 1e15);
      if (obs != std::floor(obs)) t.problem("observations", "expected an integer (a count of observations)");
      f.training.observations = static_cast<long>(obs);
      t.integer("iterations", f.training.iterations, false, 0);
      t.boolean("converged", f.training.converged);
      t.number("log_likelihood_initial", f.training.log_likelihood_initial);
      t.number("log_likelihood_final", f.training.log_likelihood_final);
    }
    if (problems->empty()) {
      for (const auto& p : f.model.problems()) problems->messages.push_back(path + ": " + p);
    }
    top.finish();
  }
  if (!problems->empty()) return make_error(problems->joined());
  return f;
}

std::string hmm_model_yaml(const HmmModelFile& f) {
  YAML::Emitter e;
  e.SetDoublePrecision(6);
  e << YAML::BeginMap;
  e << YAML::Key << "states" << YAML::Value << YAML::Flow
    << std::vector<std::string>{"push_off", "swing", "heel_strike", "stance"};
  auto matrix = [&](const char* key, const auto& m) {
    e << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (int i = 0; i < m.rows(); ++i) {
      std::vector<double> row(static_cast<std::size_t>(m.cols()));
      for (int j = 0; j < m.cols(); ++j) row[static_cast<std::size_t>(j)] = m(i, j);
      e << YAML::Flow << row;
    }
    e << YAML::EndSeq;
  };
  matrix("A", f.model.A);
  matrix("B", f.model.B);
  e << YAML::Key << "pi" << YAML::Value << YAML::Flow
    << std::vector<double>{f.model.pi(0), f.model.pi(1), f.model.pi(2), f.model.pi(3)};
  e << YAML::Key << "extraction" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "gyro_axis" << YAML::Value << f.extraction.gyro_axis;
  e << YAML::Key << "smooth_window_s" << YAML::Value << f.extraction.smooth_window_s;
  e << YAML::Key << "grade_width_deg_per_s" << YAML::Value << f.extraction.grade_width_radps * kRadToDeg;
  e << YAML::EndMap;
  e << YAML::Key << "training" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "logs" << YAML::Value << f.training.logs;
  e << YAML::Key << "observations" << YAML::Value << f.training.observations;
  e << YAML::Key << "iterations" << YAML::Value << f.training.iterations;
  e << YAML::Key << "converged" << YAML::Value << f.training.converged;
  e << YAML::Key << "log_likelihood_initial" << YAML::Value << f.training.log_likelihood_initial;
  e << YAML::Key << "log_likelihood_final" << YAML::Value << f.training.log_likelihood_final;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return "# pednav HMM zero-velocity detector model (seed 002 §3; docs/zupt.md). A[i][j] = P(j | i), B[j][k] =\n"
         "# P(grade k+1 | state j), states A push-off, B swing, C heel strike, D stance.\n" +
         std::string(e.c_str()) + "\n";
}

void read_zupt_hmm_keys(YamlMap& z, ZuptConfig& c) {
  z.number("are_threshold", c.are_threshold, false, 1e-12, 1e12);
  z.number("mag_threshold", c.mag_threshold, false, 1e-12, 1e12);
  z.text("hmm_gyro_axis", c.hmm_gyro_axis);
  int axis = 0;
  double sign = 1.0;
  if (!parse_gyro_axis(c.hmm_gyro_axis, axis, sign)) z.problem("hmm_gyro_axis", "expected x, y, z, -x, -y or -z");
  z.number("hmm_smooth_window_s", c.hmm_smooth_window_s, false, 0.0, 5.0);
  double w = c.hmm_grade_width_radps * kRadToDeg;
  z.number("hmm_grade_width_deg_per_s", w, false, 1e-3, 5000.0);
  c.hmm_grade_width_radps = w * kDegToRad;
  z.boolean("hmm_train_on_log", c.hmm_train_on_log);
  z.boolean("hmm_auto_sign", c.hmm_auto_sign);
  z.integer("hmm_max_iterations", c.hmm_max_iterations, false, 0, 100000);
  z.choice("hmm_decoder", c.hmm_decoder, {"viterbi", "forward"});
  z.number("hmm_rest_s", c.hmm_rest_s, false, 0.0, 60.0);
  z.number("hmm_min_swing_s", c.hmm_min_swing_s, false, 0.0, 5.0);
  z.number("hmm_refine_factor", c.hmm_refine_factor, false, 0.0, 1e6);
  z.number("shoe_adaptive_factor", c.shoe_adaptive_factor, false, 0.0, 1e6);
  z.number("shoe_adaptive_window_s", c.shoe_adaptive_window_s, false, 0.0, 10.0);
  double peak = c.shoe_adaptive_min_peak_radps * kRadToDeg;
  z.number("shoe_adaptive_min_peak_rate_deg_per_s", peak, false, 0.0, 1e5);
  c.shoe_adaptive_min_peak_radps = peak * kDegToRad;
  z.path("hmm_model", c.hmm_model_file);
  if (!c.hmm_model_file.empty()) {
    auto m = read_hmm_model(c.hmm_model_file);
    if (!m) {
      z.problem("hmm_model", m.error().message);
      return;
    }
    c.hmm_model = m->model;
    // The model's symbols only mean something with the extraction settings it was trained with.
    constexpr double kRelTol = 1e-6;
    const auto& x = m->extraction;
    if (x.gyro_axis != c.hmm_gyro_axis || std::abs(x.smooth_window_s - c.hmm_smooth_window_s) > kRelTol ||
        std::abs(x.grade_width_radps - c.hmm_grade_width_radps) > kRelTol * c.hmm_grade_width_radps) {
      std::ostringstream os;
      os << "trained with gyro_axis " << x.gyro_axis << ", smooth_window_s " << x.smooth_window_s
         << ", grade_width_deg_per_s " << x.grade_width_radps * kRadToDeg << "; this config has hmm_gyro_axis "
         << c.hmm_gyro_axis << ", hmm_smooth_window_s " << c.hmm_smooth_window_s << ", hmm_grade_width_deg_per_s "
         << c.hmm_grade_width_radps * kRadToDeg;
      z.problem("hmm_model", os.str());
    }
  }
}

ins::ZuptDetectorOptions zupt_detector_options(const ZuptConfig& c) {
  ins::ZuptDetectorOptions o;
  o.detector = c.detector;
  o.mv_window_s = c.mv_window_s;
  o.mv_threshold_mps2 = c.mv_threshold_mps2;
  o.mv_gyro_threshold_radps = c.mv_gyro_threshold_radps;
  o.min_time_since_step_s = c.min_time_since_step_s;
  o.shoe_window_s = c.shoe_window_s;
  o.shoe_sigma_accel_mps2 = c.shoe_sigma_accel_mps2;
  o.shoe_sigma_gyro_radps = c.shoe_sigma_gyro_radps;
  o.shoe_threshold = c.shoe_threshold;
  o.are_threshold = c.are_threshold;
  o.mag_threshold = c.mag_threshold;
  o.min_stance_s = c.min_stance_s;
  int axis = 1;
  double sign = 1.0;
  parse_gyro_axis(c.hmm_gyro_axis, axis, sign);
  o.hmm_observations.axis = axis;
  o.hmm_observations.sign = sign;
  o.hmm_observations.smooth_window_s = c.hmm_smooth_window_s;
  o.hmm_observations.grade_width_radps = c.hmm_grade_width_radps;
  o.hmm_model = c.hmm_model;
  o.hmm_train_on_log = c.hmm_train_on_log;
  o.hmm_auto_sign = c.hmm_auto_sign;
  o.hmm_max_iterations = c.hmm_max_iterations;
  o.hmm_decoder = c.hmm_decoder;
  o.hmm_rest_s = c.hmm_rest_s;
  o.hmm_min_swing_s = c.hmm_min_swing_s;
  o.hmm_refine_factor = c.hmm_refine_factor;
  o.shoe_adaptive_factor = c.shoe_adaptive_factor;
  o.shoe_adaptive_window_s = c.shoe_adaptive_window_s;
  o.shoe_adaptive_min_peak_radps = c.shoe_adaptive_min_peak_radps;
  return o;
}

}  // namespace pednav::io
