#include "schedule/reuse.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace retile {

double normalQuantileTwoSided(double p) {
  p = std::clamp(p, 1e-300, 1.0);
  // Solve erfc(z / sqrt 2) = p by bisection: monotone, and exact to the double's precision.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > p) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

ReuseTest testReuse(const std::vector<LuminanceSums>& fresh, const std::vector<LuminanceSums>& history, int width, int height,
                    double falseRejectRate, double margin) {
  ReuseTest out;
  const int bx = (width + 3) / 4, by = (height + 3) / 4;
  // Per block and for the whole tile, per quantity (luminance, R, G, B): the summed difference
  // and its variance.
  const std::size_t groups = static_cast<std::size_t>(bx * by) + 1, whole = groups - 1;
  std::vector<double> diff(groups * 4, 0.0), var(groups * 4, 0.0), base(groups * 4, 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      const LuminanceSums& f = fresh[i];
      const LuminanceSums& h = history[i];
      if (f.count < 1 || h.count < 2) continue;
      const double hm = h.sum / h.count;
      const double s2 = std::max(h.squares / h.count - hm * hm, 0.0) * h.count / (h.count - 1);
      const double w = 1.0 / f.count + 1.0 / h.count;
      double d[4] = {f.sum / f.count - hm, 0, 0, 0}, v[4] = {s2 * w, 0, 0, 0}, m[4] = {hm, 0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        const double hc = h.rgb[c] / h.count;
        m[c + 1] = hc;
        d[c + 1] = f.rgb[c] / f.count - hc;
        v[c + 1] = hm > 0.0 ? s2 * w * (hc / hm) * (hc / hm) : 0.0;
      }
      const std::size_t b = static_cast<std::size_t>((y / 4) * bx + x / 4);
      for (std::size_t g : {b, whole})
        for (std::size_t q = 0; q < 4; ++q) {
          diff[g * 4 + q] += d[q];
          var[g * 4 + q] += v[q];
          base[g * 4 + q] += m[q];
        }
      ++out.pixels;
    }
  for (std::size_t q = 0; q < 4; ++q) {
    out.diff[q] = diff[whole * 4 + q];
    out.var[q] = var[whole * 4 + q];
    out.base[q] = base[whole * 4 + q];
  }
  int tests = 0;
  for (std::size_t k = 0; k < diff.size(); ++k) {
    const double excess = std::abs(diff[k]) - margin * std::abs(base[k]);
    if (var[k] <= 0.0) {
      // No noise in the history (a flat colour): any difference beyond the margin is a change.
      if (excess > 1e-6 * (1.0 + std::abs(diff[k]))) out.statistic = std::numeric_limits<double>::infinity();
      continue;
    }
    ++tests;
    out.statistic = std::max(out.statistic, std::max(excess, 0.0) / std::sqrt(var[k]));
  }
  out.threshold = normalQuantileTwoSided(falseRejectRate / std::max(tests, 1));
  return out;
}

ReuseTest testPooled(const std::vector<const ReuseTest*>& tiles, double falseRejectRate, double margin) {
  ReuseTest out;
  for (const ReuseTest* t : tiles)
    for (int q = 0; q < 4; ++q) {
      out.diff[q] += t->diff[q];
      out.var[q] += t->var[q];
      out.base[q] += t->base[q];
      out.pixels += q == 0 ? t->pixels : 0;
    }
  int tests = 0;
  for (int q = 0; q < 4; ++q) {
    if (out.var[q] <= 0.0) continue;
    ++tests;
    out.statistic = std::max(out.statistic, std::max(std::abs(out.diff[q]) - margin * std::abs(out.base[q]), 0.0) / std::sqrt(out.var[q]));
  }
  out.threshold = normalQuantileTwoSided(falseRejectRate / std::max(tests, 1));
  return out;
}

}  // namespace retile
