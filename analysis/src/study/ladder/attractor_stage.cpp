// Stage 7 of the ladder: coexisting attractors (PointSettings::starts > 1).
//
// Besides its own initial state the point is started from starts − 1 more states in boxes about
// its motion that grow from 1.5 to 6 times the largest |x| and |v| of its tail (1 when it has
// none), so that basins near the motion and far from it are both sampled; each is run through the
// whole ladder with the same settings and matched to the attractors found so far
// (attractor_catalogue.hpp). The point's own columns stay its first start's.
#include <algorithm>
#include <cstdint>

#include "study/ladder/stages.hpp"
#include "pwl/analysis/attractor_catalogue.hpp"

namespace pwl::analysis::ladder {

namespace {

// A reproducible uniform number in [-1, 1] for start m, component c (splitmix64 of both; no
// generator state, so that every point and thread draws the same starts).
double start_coordinate(int m, Index c) {
  std::uint64_t z = 0x9e3779b97f4a7c15ULL * (static_cast<std::uint64_t>(m) * 1000003ULL +
                                            static_cast<std::uint64_t>(c) + 1ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return 2.0 * (static_cast<double>(z >> 11) * 0x1.0p-53) - 1.0;
}

}  // namespace

void attractor_stage(PointRun& run) {
  const PointSettings& s = run.settings;
  if (s.starts <= 1) return;
  const Index n = run.point.structure.dofs();
  double x_scale = 0.0, v_scale = 0.0;
  for (const Vector& y : run.tail) {
    x_scale = std::max(x_scale, y.head(n).cwiseAbs().maxCoeff());
    v_scale = std::max(v_scale, y.tail(n).cwiseAbs().maxCoeff());
  }
  x_scale = x_scale > 0.0 ? 1.5 * x_scale : 1.0;
  v_scale = v_scale > 0.0 ? 1.5 * v_scale : 1.0;
  AttractorCatalogue catalogue;
  const auto match = [&](const PointResult& r, const std::vector<Vector>& tail) {
    if (r.regime == "failed") return;
    if (r.regime != "unbounded" && tail.size() < static_cast<std::size_t>(std::max(2, r.period))) {
      return;
    }
    catalogue.match({r.regime, r.period, as_rows(tail)});
  };
  match(run.result, run.tail);
  PointSettings other = s;
  other.starts = 1;
  other.components.clear();
  other.kept_points = 0;
  for (int m = 1; m < s.starts; ++m) {
    const double grow =
        s.starts > 2 ? 1.0 + 3.0 * static_cast<double>(m - 1) / static_cast<double>(s.starts - 2)
                     : 1.0;
    Vector start(2 * n);
    for (Index c = 0; c < 2 * n; ++c) {
      start[c] = grow * (c < n ? x_scale : v_scale) * start_coordinate(m, c);
    }
    PointRun again(run.point, start, other, run.observer);
    evaluate_ladder(again);
    match(again.result, again.tail);
  }
  run.result.attractors = static_cast<int>(catalogue.attractors().size());
}

}  // namespace pwl::analysis::ladder
