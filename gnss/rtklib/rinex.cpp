// SPDX-License-Identifier: BSD-2-Clause
// RTKLIB adapter: RINEX observation and navigation reading, converted to pednav types at this boundary.
#include "gnss/rtklib/rinex.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "core/geodesy.hpp"

#include "gnss/rtklib/rtklib_c.hpp"

// Debian's librtklib is built with ENAGLO ENAGAL ENAQZS ENACMP ENAIRN NFREQ=5 NEXOBS=3: a different ABI would
// corrupt memory silently.
static_assert(sizeof(obsd_t) == 216 && MAXSAT == 221, "RTKLIB ABI mismatch: compile with Debian's definitions");

namespace pednav::gnss {
namespace {

constexpr int64_t kGpsEpochUnix_s = 315964800;  // 1980-01-06 00:00:00 in the gtime_t (Unix-like) count

// Times a record may carry: from the GPS epoch (1980-01-06) to 4e9 s later (year 2106), so that differences fit in
// int64 ns. A RINEX date far outside (fuzzing found an ephemeris week of 240101) would overflow the nanosecond count;
// RTKLIB maps an epoch year outside 1970..2099 to 1970-01-01, before the GPS epoch (docs/robustness.md).
constexpr int64_t kMaxGpsTime_s = 4'000'000'000;

bool in_range(gtime_t t) {
  const int64_t whole = static_cast<int64_t>(t.time) - kGpsEpochUnix_s;
  return whole >= 0 && whole < kMaxGpsTime_s && std::isfinite(t.sec) && std::abs(t.sec) < 2.0;
}

// Call only for in_range(t).
GpsTime from_gtime(gtime_t t) {
  const int64_t whole = static_cast<int64_t>(t.time) - kGpsEpochUnix_s;
  return GpsTime::from_ns(whole * kNsPerS + static_cast<int64_t>(std::llround(t.sec * 1e9)));
}

bool to_system(int rtk_sys, System& out) {
  switch (rtk_sys) {
    case SYS_GPS: out = System::kGps; return true;
    case SYS_GLO: out = System::kGlonass; return true;
    case SYS_GAL: out = System::kGalileo; return true;
    case SYS_CMP: out = System::kBeidou; return true;
    case SYS_QZS: out = System::kQzss; return true;
    case SYS_IRN: out = System::kIrnss; return true;
    case SYS_SBS: out = System::kSbas; return true;
    default: return false;
  }
}

bool selected(System s, const SystemSelection& sel) {
  switch (s) {
    case System::kGps: return sel.gps;
    case System::kGlonass: return sel.glonass;
    case System::kGalileo: return sel.galileo;
    case System::kBeidou: return sel.beidou;
    case System::kQzss: return sel.qzss;
    default: return false;
  }
}

// Carrier wavelength [m] of the first-frequency signal; GLONASS needs its frequency channel (-7..6).
double first_wavelength_m(System s, int glo_channel) {
  switch (s) {
    case System::kGlonass: return kSpeedOfLight_mps / (1602.0e6 + 0.5625e6 * glo_channel);
    case System::kBeidou: return kSpeedOfLight_mps / 1561.098e6;
    default: return kSpeedOfLight_mps / 1575.42e6;
  }
}

struct ObsDeleter {
  void operator()(obs_t* o) const { freeobs(o); delete o; }
};
struct NavDeleter {
  void operator()(nav_t* n) const { freenav(n, 0xFF); delete n; }
};

Expected<void> check_readable(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return make_error(path + ": file not found");
  if (!S_ISREG(st.st_mode)) return make_error(path + ": not a regular file");
  if (st.st_size == 0) return make_error(path + ": file is empty");
  return {};
}

// True when the file's last byte is a line end (a file cut off by a dying battery usually ends inside a line).
bool ends_with_newline(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return true;
  const bool ok = std::fseek(f, -1, SEEK_END) == 0 && std::fgetc(f) == '\n';
  std::fclose(f);
  return ok;
}

// Cheap pre-scan of a RINEX 3 observation body (RTKLIB silently skips event records and stops at a truncated
// record): counts epoch flags 1 and 2-5 and detects a last epoch record with fewer satellite lines than announced.
// RINEX 2 files are not scanned (their epoch lines cannot be told from data lines without decoding).
// Truncation (docs/robustness.md): RTKLIB drops a record whose satellite lines stop at the end of the file, but
// when the file ends inside the LAST satellite line of a record, RTKLIB decodes the cut numbers ("2012" from
// "20123456.789") and returns the record. `cut_inside_record` is set for that case (and, for RINEX 2, whenever the
// file does not end with a line end) so that the caller drops the last epoch.
void prescan_rinex3(const std::string& path, ObsReadStats& stats, bool& cut_inside_record) {
  const bool complete_last_line = ends_with_newline(path);
  cut_inside_record = false;
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return;
  char buf[1024];
  bool header = true;
  int expected_lines = 0;  // satellite/header lines still due for the current record
  bool in_record = false;
  bool last_is_epoch_line = false;
  bool rinex2 = false;
  while (std::fgets(buf, sizeof buf, f)) {
    const std::string line(buf);
    if (!line.empty() && line.back() != '\n' && !std::feof(f)) {  // an over-long line: skip the rest of it
      int c;
      while ((c = std::fgetc(f)) != EOF && c != '\n') {
      }
    }
    if (header) {
      if (line.find("RINEX VERSION / TYPE") != std::string::npos && line.size() > 5 && line.find_first_not_of(' ') < 9 &&
          std::atof(line.substr(0, 9).c_str()) < 3.0) {
        rinex2 = true;
        break;
      }
      if (line.find("END OF HEADER") != std::string::npos) header = false;
      continue;
    }
    if (expected_lines > 0) {
      --expected_lines;
      last_is_epoch_line = false;
      continue;
    }
    last_is_epoch_line = !line.empty() && line[0] == '>';
    if (line.empty() || line[0] != '>' || line.size() < 35) continue;
    const int flag = line[31] - '0';
    const int n = std::atoi(line.substr(32, 3).c_str());
    if (flag >= 2 && flag <= 5) ++stats.event_records;
    if (flag == 1) ++stats.power_failure_epochs;
    expected_lines = n;
    in_record = true;
  }
  std::fclose(f);
  if (rinex2) {
    stats.truncated = !complete_last_line;
    cut_inside_record = !complete_last_line;
    return;
  }
  stats.truncated = (in_record && expected_lines > 0) || !complete_last_line;
  cut_inside_record = !complete_last_line && expected_lines == 0 && !last_is_epoch_line && in_record;
}

}  // namespace

Expected<ObsData> read_rinex_obs(const std::string& path, const SystemSelection& systems) {
  if (auto ok = check_readable(path); !ok) return ok.error();
  std::unique_ptr<obs_t, ObsDeleter> obs(new obs_t{});
  std::unique_ptr<nav_t, NavDeleter> nav(new nav_t{});
  sta_t sta{};
  gtime_t t0{};
  // "-SYS=..." is not needed: systems are filtered below; signal priorities are RTKLIB's defaults (L1 C/A first).
  const int status = readrnxt(path.c_str(), 1, t0, t0, 0.0, "", obs.get(), nav.get(), &sta);
  if (status <= 0 || obs->n <= 0) {
    return make_error(path + ": no RINEX observation epochs could be read (not a RINEX obs file, or empty body)");
  }
  sortobs(obs.get());

  ObsData out;
  out.path = path;
  out.approx_position_e = Eigen::Vector3d(sta.pos[0], sta.pos[1], sta.pos[2]);
  out.has_approx_position = out.approx_position_e.norm() > 1e6;
  out.marker_name = sta.name;
  out.receiver_type = sta.rectype;

  for (int i = 0; i < obs->n; ++i) {
    const obsd_t& d = obs->data[i];
    if (!in_range(d.time)) {
      ++out.stats.records_out_of_range;
      continue;
    }
    const GpsTime t = from_gtime(d.time);
    if (out.epochs.empty() || std::abs(t - out.epochs.back().time) > 1e-6) {
      out.epochs.push_back(ObsEpoch{t, {}});
    }
    int prn = 0;
    System sys{};
    if (!to_system(satsys(d.sat, &prn), sys) || !selected(sys, systems)) continue;
    SatObs so;
    so.sat = SatId{sys, prn};
    if (d.P[0] != 0.0) so.pseudorange_m = d.P[0];
    if (d.D[0] != 0.0f) so.doppler_hz = static_cast<double>(d.D[0]);
    if (d.SNR[0] != 0) so.cn0_dbhz = d.SNR[0] * SNR_UNIT;
    if (d.L[0] != 0.0) so.carrier_cycles = d.L[0];
    so.lli = d.LLI[0];
    int channel = 0;
    if (sys == System::kGlonass && prn >= 1 && prn <= 32) channel = nav->glo_fcn[prn - 1] - 8;
    so.wavelength_m = first_wavelength_m(sys, channel);
    if (std::isnan(so.pseudorange_m) && std::isnan(so.doppler_hz)) {
      ++out.stats.sats_without_signal;
      continue;
    }
    out.epochs.back().sats.push_back(so);
  }
  bool cut_inside_record = false;
  prescan_rinex3(path, out.stats, cut_inside_record);
  if (cut_inside_record && !out.epochs.empty()) {
    out.epochs.pop_back();  // its last satellite line was cut: the numbers in it are not the receiver's
    out.stats.last_epoch_dropped = true;
  }
  // RTKLIB's sortobs orders records whose times differ by less than its DTTOL as one time (then by satellite), so
  // two epoch records a few ms apart come out interleaved: regroup by exact time, strictly increasing, one record
  // per satellite (found by fuzz_rinex).
  std::stable_sort(out.epochs.begin(), out.epochs.end(),
                   [](const ObsEpoch& a, const ObsEpoch& b) { return a.time < b.time; });
  std::vector<ObsEpoch> merged;
  merged.reserve(out.epochs.size());
  for (ObsEpoch& e : out.epochs) {
    if (merged.empty() || std::abs(e.time - merged.back().time) > 1e-6) {
      merged.push_back(std::move(e));
      continue;
    }
    for (SatObs& s : e.sats) {
      auto& into = merged.back().sats;
      if (std::any_of(into.begin(), into.end(), [&](const SatObs& o) { return o.sat == s.sat; })) {
        ++out.stats.duplicate_records;
      } else {
        into.push_back(s);
      }
    }
  }
  out.epochs = std::move(merged);
  if (out.epochs.empty()) {
    return make_error(path + (out.stats.truncated ? ": truncated: no complete observation epoch" : ": no usable observation epoch"));
  }
  out.stats.epochs_read = static_cast<int>(out.epochs.size());
  return out;
}

Expected<NavData> read_rinex_nav(const std::vector<std::string>& paths) {
  if (paths.empty()) return make_error("nav: no navigation file given");
  std::unique_ptr<nav_t, NavDeleter> nav(new nav_t{});
  gtime_t t0{};
  for (const std::string& path : paths) {
    if (auto ok = check_readable(path); !ok) return ok.error();
    const int before = nav->n + nav->ng;
    if (readrnxt(path.c_str(), 1, t0, t0, 0.0, "", nullptr, nav.get(), nullptr) <= 0 || nav->n + nav->ng == before) {
      return make_error(path + ": no broadcast ephemeris could be read (not a RINEX navigation file?)");
    }
  }
  uniqnav(nav.get());
  NavData out;
  for (int i = 0; i < nav->n; ++i) {
    const eph_t& e = nav->eph[i];
    if (!in_range(e.toe) || !in_range(e.toc) || !in_range(e.ttr)) continue;  // a garbage date: not a usable ephemeris
    int prn = 0;
    System sys{};
    if (!to_system(satsys(e.sat, &prn), sys)) continue;
    KeplerEphemeris k;
    k.sat = SatId{sys, prn};
    k.iode = e.iode;
    k.iodc = e.iodc;
    k.sv_health = e.svh;
    k.ura_index = e.sva;
    k.week = e.week;
    k.toe = from_gtime(e.toe);
    k.toc = from_gtime(e.toc);
    k.ttr = from_gtime(e.ttr);
    k.sqrt_a = std::sqrt(e.A);
    k.e = e.e;
    k.i0 = e.i0;
    k.omega0 = e.OMG0;
    k.omega = e.omg;
    k.m0 = e.M0;
    k.delta_n = e.deln;
    k.omega_dot = e.OMGd;
    k.idot = e.idot;
    k.crc = e.crc;
    k.crs = e.crs;
    k.cuc = e.cuc;
    k.cus = e.cus;
    k.cic = e.cic;
    k.cis = e.cis;
    k.toe_s = e.toes;
    k.fit_interval_h = e.fit;
    k.af0 = e.f0;
    k.af1 = e.f1;
    k.af2 = e.f2;
    k.tgd_s = e.tgd[0];
    k.beidou_geo = (sys == System::kBeidou) && (prn <= 5 || prn >= 59);
    out.kepler.push_back(k);
  }
  for (int i = 0; i < nav->ng; ++i) {
    const geph_t& g = nav->geph[i];
    if (!in_range(g.toe) || !in_range(g.tof)) continue;
    int prn = 0;
    satsys(g.sat, &prn);
    GlonassEphemeris ge;
    ge.sat = SatId{System::kGlonass, prn};
    ge.frequency_channel = g.frq;
    ge.sv_health = g.svh;
    ge.iode = g.iode;
    ge.toe = from_gtime(g.toe);
    ge.tof = from_gtime(g.tof);
    ge.p_e = Eigen::Vector3d(g.pos[0], g.pos[1], g.pos[2]);
    ge.v_e = Eigen::Vector3d(g.vel[0], g.vel[1], g.vel[2]);
    ge.a_e = Eigen::Vector3d(g.acc[0], g.acc[1], g.acc[2]);
    ge.tau_n_s = g.taun;
    ge.gamma_n = g.gamn;
    out.glonass.push_back(ge);
  }
  for (int j = 0; j < 8; ++j) out.klobuchar[j] = nav->ion_gps[j];
  out.has_klobuchar = std::any_of(out.klobuchar.begin(), out.klobuchar.end(), [](double v) { return v != 0.0; });
  return out;
}

}  // namespace pednav::gnss
