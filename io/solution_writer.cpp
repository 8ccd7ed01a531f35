// Solution writers; see io/solution_writer.hpp.
#include "io/solution_writer.hpp"

#include <fmt/format.h>

#include <cmath>

#include "core/geodesy.hpp"
#include "io/atomic_file.hpp"

namespace pednav::io {
namespace {

std::string opt(const std::optional<double>& v, const char* f = "{:.4f}") {
  return v ? fmt::format(fmt::runtime(f), *v) : std::string();
}

double signed_sqrt(double v) { return v < 0.0 ? -std::sqrt(-v) : std::sqrt(v); }

}  // namespace

std::string solution_csv_header() {
  return "gps_week,gps_tow_s,lat_deg,lon_deg,h_m,x_m,y_m,z_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,"
         "sd_n_m,sd_e_m,sd_d_m,sd_yaw_deg,n_sats_used,n_sats_rejected,zupt,hdop,pdop";
}

std::string solution_csv_line(const SolutionRow& r) {
  const Geodetic llh = geodetic_from_ecef(r.p_e);
  std::string s = fmt::format("{},{:.3f},{:.9f},{:.9f},{:.4f},{:.4f},{:.4f},{:.4f},", r.time.week(), r.time.tow_s(),
                              llh.lat * kRadToDeg, llh.lon * kRadToDeg, llh.h_m, r.p_e.x(), r.p_e.y(), r.p_e.z());
  for (int i = 0; i < 3; ++i) s += (r.v_n ? fmt::format("{:.4f}", (*r.v_n)(i)) : std::string()) + ",";
  for (int i = 0; i < 3; ++i) s += (r.rpy_deg ? fmt::format("{:.4f}", (*r.rpy_deg)(i)) : std::string()) + ",";
  s += fmt::format("{:.4f},{:.4f},{:.4f},", std::sqrt(std::max(0.0, r.cov_p_n(0, 0))),
                   std::sqrt(std::max(0.0, r.cov_p_n(1, 1))), std::sqrt(std::max(0.0, r.cov_p_n(2, 2))));
  s += opt(r.sd_yaw_deg) + ",";
  s += fmt::format("{},{},", r.n_sats_used, r.n_sats_rejected);
  s += (r.zupt ? std::string(*r.zupt ? "1" : "0") : std::string()) + ",";
  s += opt(r.hdop, "{:.2f}") + "," + opt(r.pdop, "{:.2f}");
  return s;
}

Expected<void> write_solution_csv(const std::string& path, const std::vector<SolutionRow>& rows) {
  AtomicFile f(path);
  if (!f.ok()) return make_error(path + ": cannot create the output file");
  f.stream() << solution_csv_header() << '\n';
  for (const auto& r : rows) f.stream() << solution_csv_line(r) << '\n';
  return f.commit();
}

Expected<void> write_solution_pos(const std::string& path, const std::vector<SolutionRow>& rows,
                                  const std::vector<std::string>& comment) {
  AtomicFile f(path);
  if (!f.ok()) return make_error(path + ": cannot create the output file");
  auto& o = f.stream();
  o << "% program   : pednav\n";
  for (const auto& c : comment) o << "% " << c << '\n';
  o << "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n";
  o << "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)  "
       "sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";
  for (const auto& r : rows) {
    const Geodetic llh = geodetic_from_ecef(r.p_e);
    const CalendarTime c = r.time.to_calendar_gpst();
    // NED covariance -> RTKLIB's n, e, u standard deviations and signed sqrt of the cross terms.
    const Eigen::Matrix3d& P = r.cov_p_n;
    o << fmt::format("{:04d}/{:02d}/{:02d} {:02d}:{:02d}:{:06.3f} {:14.9f} {:14.9f} {:10.4f} {:3d} {:3d} {:8.4f} {:8.4f} "
                     "{:8.4f} {:8.4f} {:8.4f} {:8.4f} {:6.2f} {:6.1f}\n",
                     c.year, c.month, c.day, c.hour, c.minute, c.second, llh.lat * kRadToDeg, llh.lon * kRadToDeg,
                     llh.h_m, r.pos_quality, r.n_sats_used, std::sqrt(std::max(0.0, P(0, 0))),
                     std::sqrt(std::max(0.0, P(1, 1))), std::sqrt(std::max(0.0, P(2, 2))), signed_sqrt(P(0, 1)),
                     signed_sqrt(-P(1, 2)), signed_sqrt(-P(2, 0)), r.age_s, 0.0);
  }
  return f.commit();
}

}  // namespace pednav::io
