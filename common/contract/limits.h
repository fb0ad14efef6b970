// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ranges every node accepts for rates and contact parameters, from a flag or a scene file alike. Each bound is
// a physical or numerical limit, not a preference; values outside are rejected with the name of the flag or field.

namespace impetus::limits {

// World rate: 0.1 Hz (a 10 s period, slower than any interactive world) to 10 kHz (above the haptic rate the world
// cannot usefully go).
inline constexpr double kMinWorldRate_Hz = 0.1;
inline constexpr double kMaxWorldRate_Hz = 10'000.0;
// Haptic rate: 100 Hz (below it a stiff contact cannot be rendered at all) to 20 kHz (what a servo thread can hold).
inline constexpr double kMinHapticRate_Hz = 100.0;
inline constexpr double kMaxHapticRate_Hz = 20'000.0;
// The haptic rate every node assumes unless told otherwise: the paper's 1 kHz (§4.2.1).
inline constexpr double kDefaultHapticRate_Hz = 1000.0;
// ODE substeps and QuickStep iterations per world step: 10^4 already costs ~1000× the defaults per step.
inline constexpr int kMaxSubsteps = 10'000;
inline constexpr int kMaxSolverIterations = 10'000;

// Contact spring: the stiffest haptic devices render ~10^5 N/m at 1 kHz; 10× that is unstable at any damping.
inline constexpr double kMaxStiffness_Npm = 1e6;
// Contact damping: 10^4 N·s/m gives 10 kN at 1 m/s, a thousand times what a desktop device can exert.
inline constexpr double kMaxDamping_Nspm = 1e4;

// A body's sizes and radii: 0.1 mm (below a device's position resolution) to 1 km. ODE's solver loses all digits when
// lengths differ by more than ~10^12; this range keeps a scene well inside that.
inline constexpr double kMinLength_m = 1e-4;
inline constexpr double kMaxLength_m = 1e3;

// Gravity: a scene's default is the Earth's (down, −z); at most 100 g, far beyond any planet a scene would model.
inline constexpr double kStandardGravity_mps2 = 9.81;
inline constexpr double kMaxGravity_mps2 = 1e3;

}  // namespace impetus::limits
