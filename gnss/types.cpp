// SPDX-License-Identifier: BSD-2-Clause
#include "gnss/types.hpp"

#include <cstdio>

namespace pednav::gnss {

char system_letter(System s) {
  switch (s) {
    case System::kGps: return 'G';
    case System::kGlonass: return 'R';
    case System::kGalileo: return 'E';
    case System::kBeidou: return 'C';
    case System::kQzss: return 'J';
    case System::kIrnss: return 'I';
    case System::kSbas: return 'S';
  }
  return '?';
}

std::string SatId::to_string() const {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%c%02d", system_letter(system), prn);
  return buf;
}

}  // namespace pednav::gnss
