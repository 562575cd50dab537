#pragma once
// Axis ticks at round numbers and their labels, for charts people read.
//
//   step candidates = m x 10^k, m in {1, 2, 2.5, 5}, k within a decade of
//                     span / (target - 1)
//   ticks           = floor(lo / step) .. ceil(hi / step), times step
//   choice          = fewest of: |count - target| + 3 (1 - span / tick span)
//                     + complexity of m (1 < 5 < 2 < 2.5), counts outside
//                     target +- 2 only when nothing else fits
// In the spirit of Heckbert (1990), "Nice numbers for graph labels", with the
// coverage and simplicity terms of Talbot, Lin & Hanrahan (2010), "An
// extension of Wilkinson's algorithm for positioning tick labels on axes".

#include <string>
#include <vector>

namespace mmm::plot {

// Tick values covering [lo, hi]: equally spaced by m x 10^k (m = 1, 2, 2.5 or
// 5), the first <= lo and the last >= hi (up to the rounding of k x step),
// aiming at `target` ticks and keeping between target - 2 and target + 2 of
// them (4..8 for 6). Zero is exactly 0 when it is a tick. lo == hi (or a span
// below 1e-9 of the magnitude, finer than labels can show) is first widened by
// 10% of the magnitude (by 1 at zero). Ticks that would overflow a double are
// dropped. Examples: (0, 97) -> 0, 20, ..., 100;
// (-0.013, 0.021) -> -0.02, -0.01, ..., 0.03; (5, 5) -> 4.5, 4.75, ..., 5.5.
// Throws InvalidInputError for non-finite bounds, lo > hi, or a target
// outside [2, 50].
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

// Labels for equally spaced ticks (as from nice_ticks): the fewest digits
// that write each tick exactly, without trailing zeros ("0.5", "10", "-20",
// "0"); scientific ("1e+06", "2.5e-05") when the largest tick is >= 1e6 or
// below 1e-3. Independent of the locale.
std::vector<std::string> tick_labels(const std::vector<double>& ticks);

}  // namespace mmm::plot
