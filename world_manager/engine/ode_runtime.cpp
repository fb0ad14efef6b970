// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/ode_runtime.h"

#include <ode/ode.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>

namespace impetus {

void ensure_ode_double_precision() {
  if (dCheckConfiguration("ODE_double_precision") == 0) {
    throw std::runtime_error(
        "ODE is not built in double precision (dCheckConfiguration(\"ODE_double_precision\") is false); install a "
        "double-precision libode (Debian's libode-dev is)");
  }
}

void init_ode_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    ensure_ode_double_precision();
    if (dInitODE2(0) == 0) throw std::runtime_error("dInitODE2 failed");
    std::atexit([] { dCloseODE(); });
  });
}

}  // namespace impetus
