#pragma once
// Levenberg-Marquardt damping shared by the iterative fits of core/fit/
// (rigid_fit.cpp, sphere_fit.cpp). Not part of the public contract.

namespace mmm::fit::detail {

// Initial damping, and the bounds beyond which the step is either plain
// Gauss-Newton or too short to matter.
inline constexpr double kInitialDamping = 1e-4;
inline constexpr double kMinDamping = 1e-12;
inline constexpr double kMaxDamping = 1e12;

}  // namespace mmm::fit::detail
