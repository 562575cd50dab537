#include "core/plot/nice_ticks.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/errors.h"
#include "core/plot/shortest_text.h"

namespace mmm::plot {

namespace {

// nice_ticks refuses targets beyond this (no axis has room for more).
constexpr int kMostTicks = 50;

// Drops the zeros after the last significant decimal ("12.50" -> "12.5",
// "3.00" -> "3", "1.50e+06" -> "1.5e+06") and the sign of zero.
std::string trim_zeros(std::string_view text) {
  const std::size_t exponent = text.find('e');
  std::string mantissa(text.substr(0, exponent));
  const std::string_view suffix = exponent == std::string_view::npos ? "" : text.substr(exponent);
  if (mantissa.find('.') != std::string::npos) {
    mantissa.erase(mantissa.find_last_not_of('0') + 1);
    if (mantissa.back() == '.') mantissa.pop_back();
  }
  if (mantissa == "-0") mantissa = "0";
  return mantissa.append(suffix);
}

// std::to_chars does not depend on the locale (snprintf would write "0,5"
// under a German one), which keeps the output deterministic.
std::string format(double value, std::chars_format style, int precision) {
  // Fixed notation of the largest double needs 309 digits plus decimals.
  std::array<char, 400> buffer{};
  const auto [end, error] =
      std::to_chars(buffer.data(), buffer.data() + buffer.size(), value, style, precision);
  if (error != std::errc{}) return "0";  // not reached: every double fits the buffer
  return trim_zeros(std::string_view(buffer.data(), static_cast<std::size_t>(end - buffer.data())));
}

using detail::shortest;

// The tick k * m * 10^e, computed so that decimal ticks come out as the
// doubles nearest them: k * m is exact, and dividing by an exact power of ten
// (10^22 is the largest double that is one) rounds once, where multiplying
// by an inexact 10^-e would round twice (3 * 0.2 = 0.6000000000000001).
double tick_value(double k, double m, int e) {
  if (e >= 0) return k * m * std::pow(10.0, e);
  if (e >= -22) return k * m / std::pow(10.0, -e);
  return k * m * std::pow(10.0, e);
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi) {
    throw InvalidInputError("nice_ticks: the range [" + shortest(lo) + ", " + shortest(hi) +
                            "] must be finite with lo <= hi");
  }
  if (target < 2 || target > kMostTicks) {
    throw InvalidInputError("nice_ticks: target is " + std::to_string(target) +
                            " ticks; it must be between 2 and " + std::to_string(kMostTicks));
  }
  constexpr double kMax = std::numeric_limits<double>::max();
  // Halves throughout: hi - lo overflows for a range across the largest doubles.
  const double magnitude = std::max(std::abs(lo), std::abs(hi));
  if (hi / 2 - lo / 2 <= magnitude * 0.5e-9) {  // a point, as far as labels can tell
    const double centre = lo / 2 + hi / 2;
    const double pad =
        centre == 0 ? 1.0 : std::max(std::abs(centre) * 0.1, std::numeric_limits<double>::min());
    lo = std::max(centre - pad, -kMax);
    hi = std::min(centre + pad, kMax);
  }
  const double half_span = hi / 2 - lo / 2;
  // Clamped so that log10 sees a positive finite number even when the
  // division underflows (a span of a few subnormals).
  const double raw_step =
      std::clamp(half_span * (2.0 / (target - 1)), std::numeric_limits<double>::denorm_min(), kMax);
  const int decade = static_cast<int>(std::floor(std::log10(raw_step)));

  struct Choice {
    double k_lo = 0, k_hi = 0, m = 1, step = 1;
    int e = 0;
    double cost = std::numeric_limits<double>::infinity();
  };
  Choice best;
  constexpr std::array<std::pair<double, double>, 4> kMultipliers = {
      {{1.0, 0.0}, {5.0, 0.1}, {2.0, 0.2}, {2.5, 0.4}}};  // m and its complexity
  const double fewest = std::max(2, target - 2);
  const double most = target + 2;
  for (int e = decade - 1; e <= decade + 1; ++e) {
    for (const auto& [m, complexity] : kMultipliers) {
      const double step = m * std::pow(10.0, e);
      if (!std::isfinite(step) || step <= 0) continue;
      // The tolerance absorbs quotients like 0.3 / 0.1 = 2.9999999999999996.
      const double k_lo = std::floor(lo / step + 1e-9);
      const double k_hi = std::ceil(hi / step - 1e-9);
      const double count = k_hi - k_lo + 1;
      const double covered = (k_hi * step) / 2 - (k_lo * step) / 2;
      const double coverage = covered > 0 ? std::min(half_span / covered, 1.0) : 0;
      double cost = std::abs(count - target) + 3 * (1 - coverage) + complexity;
      if (count < fewest || count > most) cost += 100;  // only when nothing fits
      if (cost < best.cost) best = {k_lo, k_hi, m, step, e, cost};
    }
  }
  // An integer counter: k itself can be large (around 1e9 for ticks near 1e9
  // one apart), the count is not (every candidate step is within a decade of
  // span / (target - 1)).
  const auto count = static_cast<std::size_t>(best.k_hi - best.k_lo + 1);
  std::vector<double> ticks;
  ticks.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    double tick = tick_value(best.k_lo + static_cast<double>(i), best.m, best.e);
    if (std::abs(tick) < best.step * 1e-9) tick = 0;  // no "-0" or 1e-17 for zero
    if (std::isfinite(tick)) ticks.push_back(tick);
  }
  if (ticks.size() < 2) return {lo, hi};  // the ticks overflowed: plain ends
  return ticks;
}

std::vector<std::string> tick_labels(const std::vector<double>& ticks) {
  if (ticks.empty()) return {};
  double step = ticks.size() > 1 ? std::abs(ticks[1] - ticks[0]) : std::abs(ticks[0]);
  if (!(step > 0) || !std::isfinite(step)) step = 1;
  double largest = 0;
  for (const double tick : ticks) largest = std::max(largest, std::abs(tick));
  const bool scientific = largest >= 1e6 || (largest > 0 && largest < 1e-3);
  const std::chars_format style =
      scientific ? std::chars_format::scientific : std::chars_format::fixed;
  // The fewest digits that write every tick to within a millionth of a step:
  // ticks are multiples of a decimal step, so they then read back exactly.
  std::vector<std::string> labels(ticks.size());
  for (int digits = 0; digits <= 17; ++digits) {
    bool exact = true;
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      labels[i] = ticks[i] == 0 ? "0" : format(ticks[i], style, digits);
      double back = 0;
      const std::string& label = labels[i];
      std::from_chars(label.data(), label.data() + label.size(), back);
      if (!(std::abs(back - ticks[i]) <= step * 1e-6)) exact = false;
    }
    if (exact) break;
  }
  return labels;
}

}  // namespace mmm::plot
