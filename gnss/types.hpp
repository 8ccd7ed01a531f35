// SPDX-License-Identifier: BSD-2-Clause
// Project-side GNSS types: satellites, observations, broadcast ephemerides. No RTKLIB types leak out.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/time.hpp"

namespace pednav::gnss {

enum class System : uint8_t { kGps, kGlonass, kGalileo, kBeidou, kQzss, kIrnss, kSbas };

/// One-letter RINEX system code ('G', 'R', 'E', 'C', 'J', 'I', 'S').
char system_letter(System s);

/// A satellite: constellation + PRN/slot number within it.
struct SatId {
  System system = System::kGps;
  int prn = 0;
  std::string to_string() const;  ///< e.g. "G05"
  friend bool operator==(const SatId&, const SatId&) = default;
  friend auto operator<=>(const SatId&, const SatId&) = default;
};

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One satellite's measurements on the selected signal at one receiver epoch.
struct SatObs {
  SatId sat;
  double pseudorange_m = kNaN;  ///< code pseudorange [m], NaN if absent
  double doppler_hz = kNaN;     ///< Doppler [Hz] (RINEX sign: positive when approaching); range rate = -lambda * D
  double cn0_dbhz = kNaN;       ///< carrier-to-noise density [dB-Hz], NaN if absent
  double carrier_cycles = kNaN; ///< carrier phase [cycles], NaN if absent (not used by the code/Doppler models)
  uint8_t lli = 0;              ///< loss-of-lock indicator bits (RINEX)
  double wavelength_m = kNaN;   ///< carrier wavelength of the signal [m] (GLONASS: from the frequency channel)
};

/// One receiver epoch: receiver time tag (GPST) and the satellites observed.
struct ObsEpoch {
  GpsTime time;
  std::vector<SatObs> sats;
};

/// Why epochs or records of an observation file were skipped.
struct ObsReadStats {
  int epochs_read = 0;         ///< epochs with observations returned
  int event_records = 0;       ///< epoch flags 2-5 (moving antenna, new site, header info, external event)
  int power_failure_epochs = 0;///< epoch flag 1
  int sats_without_signal = 0; ///< satellite records lacking the selected signal
  bool truncated = false;      ///< the last epoch record was incomplete (or the file ends inside a line)
  bool last_epoch_dropped = false;  ///< the file ended inside the last epoch's data: that epoch was dropped
  int records_out_of_range = 0;///< satellite records dated before 1980-01-06 or after 2106 (garbage dates): dropped
  int duplicate_records = 0;   ///< a satellite's second record at an epoch time already read: dropped (the first kept)
};

/// An observation file as pednav sees it.
struct ObsData {
  std::string path;
  std::vector<ObsEpoch> epochs;  ///< strictly increasing time
  Eigen::Vector3d approx_position_e = Eigen::Vector3d::Zero();  ///< header APPROX POSITION XYZ [m], ECEF
  bool has_approx_position = false;
  std::string marker_name;
  std::string receiver_type;
  double rinex_version = 0.0;
  ObsReadStats stats;
};

/// Keplerian broadcast ephemeris (GPS, QZSS, Galileo, BeiDou), IS-GPS-200 parameter names, SI units.
struct KeplerEphemeris {
  SatId sat;
  int iode = 0, iodc = 0, sv_health = 0, ura_index = 0;
  int week = 0;              ///< week of toe in the constellation's own week numbering as decoded by RTKLIB
  GpsTime toe, toc, ttr;     ///< reference times (GPST)
  double sqrt_a = 0, e = 0, i0 = 0, omega0 = 0, omega = 0, m0 = 0, delta_n = 0, omega_dot = 0, idot = 0;
  double crc = 0, crs = 0, cuc = 0, cus = 0, cic = 0, cis = 0;
  double toe_s = 0;          ///< toe in seconds of the constellation week
  double fit_interval_h = 0;
  double af0 = 0, af1 = 0, af2 = 0;  ///< clock polynomial [s, s/s, s/s^2]
  double tgd_s = 0;          ///< group delay (GPS TGD, Galileo BGD E1/E5a, BeiDou TGD1)
  bool beidou_geo = false;
};

/// GLONASS broadcast ephemeris (PZ-90 state vector at toe).
struct GlonassEphemeris {
  SatId sat;
  int frequency_channel = 0, sv_health = 0, iode = 0;
  GpsTime toe, tof;
  Eigen::Vector3d p_e = Eigen::Vector3d::Zero(), v_e = Eigen::Vector3d::Zero(), a_e = Eigen::Vector3d::Zero();
  double tau_n_s = 0, gamma_n = 0;
};

/// Merged broadcast navigation data of one or more nav files.
struct NavData {
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  std::array<double, 8> klobuchar{};  ///< GPS alpha0..3, beta0..3 (zero if absent)
  bool has_klobuchar = false;
};

}  // namespace pednav::gnss
