// SPDX-License-Identifier: BSD-2-Clause
// `pednav zupt CONFIG.yaml -o OUT` and `pednav hmm-train CONFIG.yaml... -o hmm.yaml`: thin registrations; the work
// is pipeline::run_zupt_command / pipeline::run_hmm_train_command.
#include <spdlog/spdlog.h>

#include <cstdio>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "pipeline/zupt_command.hpp"

namespace pednav::apps {
namespace {

// The 4 x 4 transition matrix, one row per line, for the log.
std::string matrix_text(const Eigen::Matrix4d& A) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    s += fmt::format("  {}: ", ins::gait_state_letter(i));
    for (int j = 0; j < 4; ++j) s += fmt::format("{:8.4f}", A(i, j));
    s += "\n";
  }
  return s;
}

}  // namespace

void add_zupt_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("zupt", "Run the configured zero-velocity detector (zupt.detector) over the IMU log");
  auto path = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto detector = std::make_shared<std::string>();
  cmd->add_option("CONFIG", *path, "Run configuration (YAML): imu and zupt sections")->required();
  cmd->add_option("-o,--output", *out, "Output folder (zupt.csv, summary.json)")->required();
  cmd->add_option("--detector", *detector, "Override zupt.detector")
      ->check(CLI::IsMember({"shoe", "mv", "are", "mag", "hmm", "labels"}));
  cmd->callback([&action, path, out, detector] {
    action = [path, out, detector] {
      auto cfg = io::load_run_config(*path);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      if (!detector->empty()) cfg->zupt.detector = *detector;
      auto sum = pipeline::run_zupt_command(*cfg, *out);
      if (!sum) {
        spdlog::error("{}", sum.error().message);
        return 1;
      }
      spdlog::info("zupt ({}): {} of {} samples stance in {} intervals, {} steps, {:.2f} s -> {}", sum->detector,
                   sum->stance_samples, sum->samples, sum->stance_intervals, sum->steps, sum->wall_s, *out);
      if (sum->label_stance_samples >= 0) {
        spdlog::info("against the log's {} labelled stance samples: precision {:.3f}, recall {:.3f}",
                     sum->label_stance_samples, sum->label_precision, sum->label_recall);
      }
      if (sum->detector == "hmm") {
        spdlog::info("hmm: {} observations, {} Baum-Welch iterations on the log; transition matrix A (rows "
                     "from, columns to A B C D):\n{}",
                     sum->hmm_observations, sum->hmm_iterations, matrix_text(sum->hmm_model.A));
      }
      return 0;
    };
  });
}

void add_hmm_train_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("hmm-train", "Train the HMM zero-velocity detector (Baum-Welch) on one or more logs");
  auto paths = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto iterations = std::make_shared<int>(200);
  cmd->add_option("CONFIG", *paths, "Run configurations (YAML): imu and zupt.hmm_* keys, one per log")->required();
  cmd->add_option("-o,--output", *out, "Model file to write (hmm.yaml)")->required();
  cmd->add_option("--iterations", *iterations, "Baum-Welch iterations at most (default 200)")
      ->check(CLI::Range(0, 100000));
  cmd->callback([&action, paths, out, iterations] {
    action = [paths, out, iterations] {
      std::vector<io::RunConfig> cfgs;
      for (const auto& p : *paths) {
        auto cfg = io::load_run_config(p);
        if (!cfg) {
          spdlog::error("{}", cfg.error().message);
          return 1;
        }
        cfgs.push_back(std::move(*cfg));
      }
      auto f = pipeline::run_hmm_train_command(cfgs, *out, *iterations);
      if (!f) {
        spdlog::error("{}", f.error().message);
        return 1;
      }
      spdlog::info("hmm-train: {} logs, {} observations, {} iterations ({}), log-likelihood {:.2f} -> {:.2f} -> {}",
                   f->training.logs.size(), f->training.observations, f->training.iterations,
                   f->training.converged ? "converged" : "not converged", f->training.log_likelihood_initial,
                   f->training.log_likelihood_final, *out);
      std::fputs(("transition matrix A (rows from, columns to A B C D):\n" + matrix_text(f->model.A)).c_str(), stdout);
      return 0;
    };
  });
}

}  // namespace pednav::apps
