// SPDX-License-Identifier: Apache-2.0
#pragma once
// Process-wide ODE set-up. ODE keeps global state (its allocator, its random generator), so the process initialises it
// once — the daemon's main and the test programs call init_ode_once() before building any World — and a World never
// calls dInitODE2 itself.

namespace impetus {

// Throws std::runtime_error when the linked ODE is not double precision: the world link carries doubles and the
// scenes' millimetre contacts need them.
void ensure_ode_double_precision();

// dInitODE2(0) the first time it is called (thread-safe); later calls do nothing. Checks the precision first.
// ODE is closed by an atexit handler, after every World has been destroyed.
void init_ode_once();

}  // namespace impetus
