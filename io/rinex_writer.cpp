// SPDX-License-Identifier: BSD-2-Clause
// RINEX 3.04 writers (format description RINEX 3.04, Tables A1-A6). Fixed-width fields; header labels in
// columns 61-80.
#include "io/rinex_writer.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/atomic_file.hpp"

namespace pednav::io {
namespace {

void header_line(std::string& out, const std::string& content, const char* label) {
  std::string c = content.substr(0, 60);
  c.resize(60, ' ');
  out += c;
  out += label;
  out += '\n';
}
void rtrim_line(std::string& s) {
  while (!s.empty() && s.back() == ' ') s.pop_back();
}
std::string date_line(const std::string& program, GpsTime t) {
  const CalendarTime c = t.to_calendar_gpst();
  return fmt::format("{:<20}{:<20}{:04d}{:02d}{:02d} {:02d}{:02d}{:02d} GPS", program, "pednav", c.year, c.month, c.day,
                     c.hour, c.minute, static_cast<int>(c.second));
}
// Calendar GPST with the seconds computed from integer nanoseconds (no rounding surprises).
struct Cal {
  int y, mo, d, h, mi;
  double s;
};
Cal calendar(GpsTime t) {
  const int64_t ns_of_min = ((t.ns() % (60 * kNsPerS)) + 60 * kNsPerS) % (60 * kNsPerS);
  const CalendarTime c = GpsTime::from_ns(t.ns() - ns_of_min).to_calendar_gpst();
  return {c.year, c.month, c.day, c.hour, c.minute, static_cast<double>(ns_of_min) * 1e-9};
}
std::string d19(double v) { return fmt::format("{:19.12E}", v); }

}  // namespace

Expected<std::string> format_rinex_obs(const gnss::ObsData& obs, const RinexObsHeader& hdr) {
  if (obs.epochs.empty()) return make_error("RINEX obs writer: no epochs to write (marker " + obs.marker_name + ")");
  std::string out;
  out.reserve(obs.epochs.size() * 600 + 2000);
  header_line(out, fmt::format("{:9.2f}{:11}{:<20}{:<20}", 3.04, "", "OBSERVATION DATA", "G: GPS"), "RINEX VERSION / TYPE");
  header_line(out, date_line(hdr.program, obs.epochs.front().time), "PGM / RUN BY / DATE");
  header_line(out, "simulated data: pednav simulate (docs/sim.md)", "COMMENT");
  header_line(out, obs.marker_name.empty() ? "UNKNOWN" : obs.marker_name, "MARKER NAME");
  header_line(out, "NON_GEODETIC", "MARKER TYPE");
  header_line(out, fmt::format("{:<20}{:<40}", "pednav", "pednav"), "OBSERVER / AGENCY");
  header_line(out, fmt::format("{:<20}{:<20}{:<20}", "SIM-1", hdr.receiver_type, "1.0"), "REC # / TYPE / VERS");
  header_line(out, fmt::format("{:<20}{:<20}", "SIM-1", hdr.antenna_type), "ANT # / TYPE");
  const Eigen::Vector3d& p = obs.approx_position_e;
  header_line(out, fmt::format("{:14.4f}{:14.4f}{:14.4f}", p.x(), p.y(), p.z()), "APPROX POSITION XYZ");
  header_line(out, fmt::format("{:14.4f}{:14.4f}{:14.4f}", 0.0, 0.0, 0.0), "ANTENNA: DELTA H/E/N");
  bool carrier = false;  // L1C column only when a phase is present: code-only files stay as they were
  for (const auto& e : obs.epochs)
    for (const auto& s : e.sats) carrier = carrier || std::isfinite(s.carrier_cycles);
  header_line(out, carrier ? "G    4 C1C L1C D1C S1C" : "G    3 C1C D1C S1C", "SYS / # / OBS TYPES");
  header_line(out, "DBHZ", "SIGNAL STRENGTH UNIT");
  if (carrier) header_line(out, "G L1C  0.00000", "SYS / PHASE SHIFT");
  header_line(out, fmt::format("{:10.3f}", hdr.interval_s), "INTERVAL");
  const Cal c0 = calendar(obs.epochs.front().time);
  header_line(out, fmt::format("{:6d}{:6d}{:6d}{:6d}{:6d}{:13.7f}     GPS", c0.y, c0.mo, c0.d, c0.h, c0.mi, c0.s),
              "TIME OF FIRST OBS");
  const Cal c1 = calendar(obs.epochs.back().time);
  header_line(out, fmt::format("{:6d}{:6d}{:6d}{:6d}{:6d}{:13.7f}     GPS", c1.y, c1.mo, c1.d, c1.h, c1.mi, c1.s),
              "TIME OF LAST OBS");
  header_line(out, "", "END OF HEADER");
  auto field = [](double v) { return std::isfinite(v) ? fmt::format("{:14.3f}  ", v) : std::string(16, ' '); };
  for (const auto& e : obs.epochs) {
    const Cal c = calendar(e.time);
    out += fmt::format("> {:4d} {:02d} {:02d} {:02d} {:02d}{:11.7f}  0{:3d}\n", c.y, c.mo, c.d, c.h, c.mi, c.s, e.sats.size());
    for (const auto& s : e.sats) {
      std::string line = fmt::format("G{:02d}", s.sat.prn) + field(s.pseudorange_m);
      if (carrier) {  // F14.3, LLI digit (blank when 0), blank signal strength
        line += std::isfinite(s.carrier_cycles)
                    ? fmt::format("{:14.3f}", s.carrier_cycles) + (s.lli != 0 ? char('0' + (s.lli & 7)) : ' ') + ' '
                    : std::string(16, ' ');
      }
      line += field(s.doppler_hz) + field(s.cn0_dbhz);
      rtrim_line(line);
      out += line;
      out += '\n';
    }
  }
  return out;
}

Expected<std::string> format_rinex_nav(const gnss::NavData& nav) {
  if (nav.kepler.empty()) return make_error("RINEX nav writer: no ephemerides to write");
  std::string out;
  out.reserve(nav.kepler.size() * 700 + 1000);
  header_line(out, fmt::format("{:9.2f}{:11}{:<20}{:<20}", 3.04, "", "N: GNSS NAV DATA", "G: GPS"), "RINEX VERSION / TYPE");
  header_line(out, date_line("pednav simulate", nav.kepler.front().toc), "PGM / RUN BY / DATE");
  header_line(out, "nominal GPS constellation of pednav simulate (docs/sim.md)", "COMMENT");
  if (nav.has_klobuchar) {
    const auto& k = nav.klobuchar;
    header_line(out, fmt::format("GPSA {:12.4E}{:12.4E}{:12.4E}{:12.4E}", k[0], k[1], k[2], k[3]), "IONOSPHERIC CORR");
    header_line(out, fmt::format("GPSB {:12.4E}{:12.4E}{:12.4E}{:12.4E}", k[4], k[5], k[6], k[7]), "IONOSPHERIC CORR");
  }
  header_line(out, fmt::format("{:6d}", 18), "LEAP SECONDS");
  header_line(out, "", "END OF HEADER");
  for (const auto& e : nav.kepler) {
    if (e.sat.system != gnss::System::kGps) return make_error("RINEX nav writer: only GPS ephemerides are written (" + e.sat.to_string() + ")");
    const Cal c = calendar(e.toc);
    out += fmt::format("G{:02d} {:4d} {:02d} {:02d} {:02d} {:02d} {:02d}", e.sat.prn, c.y, c.mo, c.d, c.h, c.mi,
                       static_cast<int>(c.s)) +
           d19(e.af0) + d19(e.af1) + d19(e.af2) + "\n";
    auto orbit = [&](double a, double b, double c2, double d) { out += "    " + d19(a) + d19(b) + d19(c2) + d19(d) + "\n"; };
    orbit(e.iode, e.crs, e.delta_n, e.m0);
    orbit(e.cuc, e.e, e.cus, e.sqrt_a);
    orbit(e.toe_s, e.cic, e.omega0, e.cis);
    orbit(e.i0, e.crc, e.omega, e.omega_dot);
    orbit(e.idot, 1.0, e.week, 0.0);
    orbit(2.0, e.sv_health, e.tgd_s, e.iodc);
    out += "    " + d19(e.ttr.tow_s()) + d19(e.fit_interval_h) + "\n";
  }
  return out;
}

Expected<void> write_rinex_obs(const std::string& path, const gnss::ObsData& obs, const RinexObsHeader& header) {
  auto text = format_rinex_obs(obs, header);
  if (!text) return text.error();
  return write_file_atomic(path, *text);
}

Expected<void> write_rinex_nav(const std::string& path, const gnss::NavData& nav) {
  auto text = format_rinex_nav(nav);
  if (!text) return text.error();
  return write_file_atomic(path, *text);
}

}  // namespace pednav::io
