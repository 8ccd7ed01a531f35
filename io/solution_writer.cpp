// SPDX-License-Identifier: BSD-2-Clause
// Solution writers; see io/solution_writer.hpp.
#include "io/solution_writer.hpp"

#include <fmt/compile.h>
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "io/atomic_file.hpp"

namespace pednav::io {
namespace {

double signed_sqrt(double v) { return v < 0.0 ? -std::sqrt(-v) : std::sqrt(v); }

}  // namespace

std::string solution_csv_header(bool carrier) {
  std::string h = "gps_week,gps_tow_s,lat_deg,lon_deg,h_m,x_m,y_m,z_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,"
                  "sd_n_m,sd_e_m,sd_d_m,sd_yaw_deg,n_sats_used,n_sats_rejected,zupt,hdop,pdop";
  if (carrier) h += ",solution_status,n_fixed_ambiguities,ar_ratio";
  return h;
}

std::string solution_csv_line(const SolutionRow& r) {
  // Compiled format strings (FMT_COMPILE: parsed at compile time, the same output as the run-time ones; writing
  // the rows was a twentieth of an INS/ZUPT run, most of it parsing the format strings).
  const Geodetic llh = geodetic_from_ecef(r.p_e);
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, FMT_COMPILE("{},{:.3f},{:.9f},{:.9f},{:.4f},{:.4f},{:.4f},{:.4f},"), r.time.week(), r.time.tow_s(),
                 llh.lat * kRadToDeg, llh.lon * kRadToDeg, llh.h_m, r.p_e.x(), r.p_e.y(), r.p_e.z());
  for (int i = 0; i < 3; ++i) {
    if (r.v_n) fmt::format_to(out, FMT_COMPILE("{:.4f}"), (*r.v_n)(i));
    b.push_back(',');
  }
  for (int i = 0; i < 3; ++i) {
    if (r.rpy_deg) fmt::format_to(out, FMT_COMPILE("{:.4f}"), (*r.rpy_deg)(i));
    b.push_back(',');
  }
  fmt::format_to(out, FMT_COMPILE("{:.4f},{:.4f},{:.4f},"), std::sqrt(std::max(0.0, r.cov_p_n(0, 0))),
                 std::sqrt(std::max(0.0, r.cov_p_n(1, 1))), std::sqrt(std::max(0.0, r.cov_p_n(2, 2))));
  if (r.sd_yaw_deg) fmt::format_to(out, FMT_COMPILE("{:.4f}"), *r.sd_yaw_deg);
  fmt::format_to(out, FMT_COMPILE(",{},{},"), r.n_sats_used, r.n_sats_rejected);
  if (r.zupt) b.push_back(*r.zupt ? '1' : '0');
  b.push_back(',');
  if (r.hdop) fmt::format_to(out, FMT_COMPILE("{:.2f}"), *r.hdop);
  b.push_back(',');
  if (r.pdop) fmt::format_to(out, FMT_COMPILE("{:.2f}"), *r.pdop);
  if (r.solution_status) {
    fmt::format_to(out, FMT_COMPILE(",{},{},{:.2f}"), r.solution_status, r.n_fixed_ambiguities, r.ar_ratio);
  }
  return fmt::to_string(b);
}

Expected<void> write_solution_csv(const std::string& path, const std::vector<SolutionRow>& rows) {
  AtomicFile f(path);
  if (!f.ok()) return make_error(path + ": cannot create the output file");
  const bool carrier = std::any_of(rows.begin(), rows.end(), [](const SolutionRow& r) { return r.solution_status; });
  f.stream() << solution_csv_header(carrier) << '\n';
  for (const auto& r : rows) {
    f.stream() << solution_csv_line(r);
    if (carrier && !r.solution_status) f.stream() << ",,,";
    f.stream() << '\n';
  }
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
    o << fmt::format(FMT_COMPILE("{:04d}/{:02d}/{:02d} {:02d}:{:02d}:{:06.3f} {:14.9f} {:14.9f} {:10.4f} {:3d} {:3d} "
                                 "{:8.4f} {:8.4f} {:8.4f} {:8.4f} {:8.4f} {:8.4f} {:6.2f} {:6.1f}\n"),
                     c.year, c.month, c.day, c.hour, c.minute, c.second, llh.lat * kRadToDeg, llh.lon * kRadToDeg,
                     llh.h_m, r.pos_quality, r.n_sats_used, std::sqrt(std::max(0.0, P(0, 0))),
                     std::sqrt(std::max(0.0, P(1, 1))), std::sqrt(std::max(0.0, P(2, 2))), signed_sqrt(P(0, 1)),
                     signed_sqrt(-P(1, 2)), signed_sqrt(-P(2, 0)), r.age_s, std::min(r.ar_ratio, 9999.9));
  }
  return f.commit();
}

namespace {

struct Ellipse {
  double major_m = 0.0, minor_m = 0.0, orientation_deg = 0.0;  // 1σ semi-axes, major axis clockwise from north
};

// The per-epoch values both map formats carry: position and σ.
struct EpochMapValues {
  double lon_deg, lat_deg, h_m, sd_n_m, sd_e_m, sd_d_m;
};
Ellipse horizontal_ellipse(const Eigen::Matrix3d& cov_n) {
  const Eigen::Matrix2d c = cov_n.topLeftCorner<2, 2>();  // N, E
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(c);
  Ellipse e;
  e.major_m = std::sqrt(std::max(0.0, es.eigenvalues()(1)));
  e.minor_m = std::sqrt(std::max(0.0, es.eigenvalues()(0)));
  const Eigen::Vector2d v = es.eigenvectors().col(1);  // (north, east)
  double az = std::atan2(v.y(), v.x()) * kRadToDeg;
  if (az < 0.0) az += 180.0;
  if (az >= 180.0) az -= 180.0;
  e.orientation_deg = az;
  return e;
}

EpochMapValues map_values(const SolutionRow& r) {
  const Geodetic g = geodetic_from_ecef(r.p_e);
  return {g.lon * kRadToDeg, g.lat * kRadToDeg, g.h_m, std::sqrt(std::max(0.0, r.cov_p_n(0, 0))),
          std::sqrt(std::max(0.0, r.cov_p_n(1, 1))), std::sqrt(std::max(0.0, r.cov_p_n(2, 2)))};
}

std::string utc_iso(GpsTime t) {
  const CalendarTime c = t.to_utc();
  return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:06.3f}Z", c.year, c.month, c.day, c.hour, c.minute, c.second);
}

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    if (ch == '"' || ch == '\\') o += '\\';
    if (static_cast<unsigned char>(ch) < 0x20) {
      o += fmt::format("\\u{:04x}", static_cast<int>(ch));
      continue;
    }
    o += ch;
  }
  return o;
}

}  // namespace

Expected<void> write_solution_geojson(const std::string& path, const std::vector<SolutionRow>& rows,
                                      const std::string& title) {
  std::string o = "{\"type\": \"FeatureCollection\", \"name\": \"" + json_escape(title) + "\", \"features\": [\n";
  o += "{\"type\": \"Feature\", \"properties\": {\"name\": \"track\", \"epochs\": " + std::to_string(rows.size()) +
       "}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [";
  for (size_t i = 0; i < rows.size(); ++i) {
    const Geodetic g = geodetic_from_ecef(rows[i].p_e);
    o += fmt::format("{}[{:.9f}, {:.9f}, {:.4f}]", i ? ", " : "", g.lon * kRadToDeg, g.lat * kRadToDeg, g.h_m);
  }
  o += "]}}";
  for (const SolutionRow& r : rows) {
    const EpochMapValues v = map_values(r);
    const Ellipse e = horizontal_ellipse(r.cov_p_n);
    o += fmt::format(
        ",\n{{\"type\": \"Feature\", \"geometry\": {{\"type\": \"Point\", \"coordinates\": [{:.9f}, {:.9f}, {:.4f}]}}, "
        "\"properties\": {{\"gps_week\": {}, \"gps_tow_s\": {:.3f}, \"utc\": \"{}\", \"sd_n_m\": {:.4f}, \"sd_e_m\": {:.4f}, "
        "\"sd_d_m\": {:.4f}, \"sigma_major_m\": {:.4f}, \"sigma_minor_m\": {:.4f}, \"orientation_deg\": {:.2f}, "
        "\"n_sats_used\": {}, \"zupt\": {}}}}}",
        v.lon_deg, v.lat_deg, v.h_m, r.time.week(), r.time.tow_s(), utc_iso(r.time), v.sd_n_m, v.sd_e_m, v.sd_d_m,
        e.major_m, e.minor_m, e.orientation_deg, r.n_sats_used, r.zupt ? (*r.zupt ? "true" : "false") : "null");
  }
  o += "\n]}\n";
  return write_file_atomic(path, o);
}

Expected<void> write_solution_kml(const std::string& path, const std::vector<SolutionRow>& rows, const std::string& title) {
  std::string o = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n";
  o += "<name>" + xml_escape(title) + "</name>\n";
  o += "<Style id=\"track\"><LineStyle><color>ff0000ff</color><width>2</width></LineStyle></Style>\n";
  o += "<Style id=\"epoch\"><IconStyle><scale>0.4</scale></IconStyle><LabelStyle><scale>0</scale></LabelStyle></Style>\n";
  o += "<Placemark><name>track</name><styleUrl>#track</styleUrl><LineString><altitudeMode>clampToGround</altitudeMode>"
       "<coordinates>\n";
  for (const SolutionRow& r : rows) {
    const Geodetic g = geodetic_from_ecef(r.p_e);
    o += fmt::format("{:.9f},{:.9f},{:.4f}\n", g.lon * kRadToDeg, g.lat * kRadToDeg, g.h_m);
  }
  o += "</coordinates></LineString></Placemark>\n<Folder><name>epochs</name>\n";
  for (const SolutionRow& r : rows) {
    const EpochMapValues v = map_values(r);
    const Ellipse e = horizontal_ellipse(r.cov_p_n);
    o += fmt::format(
        "<Placemark><name>{:.3f}</name><styleUrl>#epoch</styleUrl><TimeStamp><when>{}</when></TimeStamp>"
        "<ExtendedData><Data name=\"gps_week\"><value>{}</value></Data><Data name=\"gps_tow_s\"><value>{:.3f}</value></Data>"
        "<Data name=\"sd_n_m\"><value>{:.4f}</value></Data><Data name=\"sd_e_m\"><value>{:.4f}</value></Data>"
        "<Data name=\"sd_d_m\"><value>{:.4f}</value></Data><Data name=\"sigma_major_m\"><value>{:.4f}</value></Data>"
        "<Data name=\"sigma_minor_m\"><value>{:.4f}</value></Data><Data name=\"orientation_deg\"><value>{:.2f}</value></Data>"
        "<Data name=\"n_sats_used\"><value>{}</value></Data></ExtendedData>"
        "<Point><coordinates>{:.9f},{:.9f},{:.4f}</coordinates></Point></Placemark>\n",
        r.time.tow_s(), utc_iso(r.time), r.time.week(), r.time.tow_s(), v.sd_n_m, v.sd_e_m, v.sd_d_m, e.major_m,
        e.minor_m, e.orientation_deg, r.n_sats_used, v.lon_deg, v.lat_deg, v.h_m);
  }
  o += "</Folder>\n</Document>\n</kml>\n";
  return write_file_atomic(path, o);
}

}  // namespace pednav::io
