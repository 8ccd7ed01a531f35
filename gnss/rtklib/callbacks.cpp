// SPDX-License-Identifier: BSD-2-Clause
// The three callbacks librtklib expects its executable to define. pednav reports through return values
// instead, so they do nothing. Forced into every binary through -Wl,-u (gnss/CMakeLists.txt).
#include "gnss/rtklib/rtklib_c.hpp"

extern "C" {
int showmsg(const char* /*format*/, ...) { return 0; }
void settspan(gtime_t /*ts*/, gtime_t /*te*/) {}
void settime(gtime_t /*time*/) {}
}
