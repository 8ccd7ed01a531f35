// SPDX-License-Identifier: BSD-2-Clause
#include "io/residuals_writer.hpp"

#include <fmt/format.h>

#include "io/atomic_file.hpp"

namespace pednav::io {

Expected<void> write_residuals_csv(const std::string& path, const std::vector<fusion::GnssRowRecord>& records) {
  // w_final is the last column (added after the others): the columns before it keep their order.
  std::string s = "gps_week,gps_tow_s,sat,type,innovation,sigma,w,mdb,rejected,w_final\n";
  s.reserve(s.size() + records.size() * 72);
  for (const auto& r : records) {
    s += fmt::format("{},{:.3f},{},{},{:.4f},{:.4f},{:.3f},{:.4f},{},{:.3f}\n", r.t.week(), r.t.tow_s(),
                     r.sat.to_string(), r.doppler ? "doppler" : "code", r.innovation, r.sigma, r.w, r.mdb,
                     r.rejected ? 1 : 0, r.w_final);
  }
  return write_file_atomic(path, s);
}

}  // namespace pednav::io
