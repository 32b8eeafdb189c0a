// The banded exponential of He, Gao & Zhong, "An efficient numerical method for computing dynamic
// responses of periodic piecewise linear systems", Appl. Math. Mech. 39(7) (2018) 737-749, §2:
// the exponential of a periodic structure has identical and zero entries, so it is read off the
// exponential of a small substructure. Extended here to structures whose cells differ (one
// substructure per block of rows) and to the load integrals of the step. The exponentials are
// those of the precise integration method (Zhong & Williams, Proc. IMechE C 208 (1994) 427-430).
#include "pwl/numerics/banded_exponential.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <unordered_map>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/substructure_exponential.hpp"
#include "numerics/row_blocks.hpp"
#include "numerics/serial_products.hpp"

namespace pwl {

namespace banded_detail {

std::vector<RowBlock> partition_rows(Index n, Index margin, Index cell) {
  std::vector<RowBlock> blocks;
  const Index step = cell > 0 ? cell : std::max<Index>(1, margin);
  const Index left = cell > 0 ? std::max<Index>(cell, (margin + cell - 1) / cell * cell) : step;
  const auto add = [&](Index b, Index e) {
    blocks.push_back({b, e, std::max<Index>(0, b - margin), std::min(n, e + margin)});
  };
  if (left + margin >= n) {
    add(0, n);
    return blocks;
  }
  add(0, left);
  Index r = left;
  while (r + step + margin <= n) {
    add(r, r + step);
    r += step;
  }
  if (r < n) add(r, n);
  return blocks;
}

}  // namespace banded_detail

Vector interleave_state(const Vector& x, const Vector& v) {
  if (x.size() != v.size()) {
    throw InputError(fmt::format("interleave_state: {} displacements and {} velocities", x.size(),
                                 v.size()));
  }
  Vector s(2 * x.size());
  for (Index i = 0; i < x.size(); ++i) {
    s[2 * i] = x[i];
    s[2 * i + 1] = v[i];
  }
  return s;
}

void deinterleave_state(const Vector& state, Vector& x, Vector& v) {
  const Index n = state.size() / 2;
  x.resize(n);
  v.resize(n);
  for (Index i = 0; i < n; ++i) {
    x[i] = state[2 * i];
    v[i] = state[2 * i + 1];
  }
}

bool BandedExponentialOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    *why = fmt::format("tolerance = {} must be in (0, 1)", tolerance);
    return false;
  }
  if (band < 0) {
    *why = fmt::format("band = {} must be >= 0 (0: from the tolerance)", band);
    return false;
  }
  if (guard < 0) {
    *why = fmt::format("guard = {} must be >= 0", guard);
    return false;
  }
  if (cell_dofs < 0) {
    *why = fmt::format("cell_dofs = {} must be >= 0 (0: detect)", cell_dofs);
    return false;
  }
  if (max_band < 1) {
    *why = fmt::format("max_band = {} must be >= 1", max_band);
    return false;
  }
  if (band > max_band) {
    *why = fmt::format("band = {} exceeds max_band = {}", band, max_band);
    return false;
  }
  return exponential.is_valid(why);
}

namespace {

using banded_detail::CellRepeats;
using banded_detail::RowBlock;
using banded_detail::repeats_block;
using banded_detail::partition_rows;

// The operator blocks whose dropped parts are measured: the four blocks of T, and the
// displacement and velocity rows of the two linear-load integrals.
constexpr int kTransitionBlocks = 0;  // + 2a + b: rows x (a = 0) or x' (a = 1), columns x or x'
constexpr int kRisingBlocks = 4;      // + a
constexpr int kFallingBlocks = 6;     // + a
constexpr int kBlockTypes = 8;

std::string block_name(int type) {
  const char* row[2] = {"x", "x'"};
  if (type < kRisingBlocks) {
    return fmt::format("T[{} from {}]", row[type / 2], row[type % 2]);
  }
  if (type < kFallingBlocks) return fmt::format("rising load integral, {} rows", row[type - 4]);
  return fmt::format("falling load integral, {} rows", row[type - 6]);
}

// Largest (over rows) row sum and tail sums beyond each distance, per block type.
struct Profiles {
  std::vector<double> norm;               // [type]
  std::vector<std::vector<double>> tail;  // [type][d], d = 0..margin
  std::vector<double> by_distance;        // scratch

  Profiles(int types, Index margin)
      : norm(static_cast<std::size_t>(types), 0.0),
        tail(static_cast<std::size_t>(types),
             std::vector<double>(static_cast<std::size_t>(margin + 1), 0.0)) {}

  // Adds one row: magnitude(lj) for the window's columns lj = 0..w-1, the row at distance
  // |first + lj - i| from the row's degree of freedom i.
  template <class Magnitude>
  void add(int type, Index i, Index first, Index w, const Magnitude& magnitude) {
    by_distance.assign(static_cast<std::size_t>(w + std::abs(i - first) + 1), 0.0);
    double total = 0.0;
    for (Index lj = 0; lj < w; ++lj) {
      const double a = magnitude(lj);
      by_distance[static_cast<std::size_t>(std::abs(first + lj - i))] += a;
      total += a;
    }
    auto& t = tail[static_cast<std::size_t>(type)];
    norm[static_cast<std::size_t>(type)] = std::max(norm[static_cast<std::size_t>(type)], total);
    // Tails summed from the far end, so that a tail of 1e-20 is not lost against the row's O(1)
    // entries; by_distance then holds the suffix sums.
    for (std::size_t d = by_distance.size() - 1; d-- > 0;) by_distance[d] += by_distance[d + 1];
    for (std::size_t d = 0; d < t.size(); ++d) {
      const double beyond = d + 1 < by_distance.size() ? by_distance[d + 1] : 0.0;
      t[d] = std::max(t[d], beyond);
    }
  }

  // Smallest d in 0..margin with every block's tail within tol of its norm, or -1.
  Index band_for(double tol) const {
    const std::size_t depth = tail.empty() ? 0 : tail[0].size();
    for (std::size_t d = 0; d < depth; ++d) {
      bool ok = true;
      for (std::size_t t = 0; t < tail.size() && ok; ++t) ok = tail[t][d] <= tol * norm[t];
      if (ok) return static_cast<Index>(d);
    }
    return -1;
  }

  // Largest tail/norm at distance d, and where.
  double ratio_at(Index d, int* worst) const {
    double r = 0.0;
    *worst = 0;
    for (std::size_t t = 0; t < tail.size(); ++t) {
      if (norm[t] <= 0.0) continue;
      const double v = tail[t][static_cast<std::size_t>(d)] / norm[t];
      if (v > r) {
        r = v;
        *worst = static_cast<int>(t);
      }
    }
    return r;
  }
};

// Adds the profiles of row i (rows x_i and x_i') of a substructure exponential whose window
// starts at degree of freedom `first` (a shared exponential may have been computed for another
// window with the same content).
void add_profiles(Profiles& p, const SubstructureExponential& e, Index first, Index i) {
  const Index w = e.size, li = i - first;
  for (int a = 0; a < 2; ++a) {
    const Index row = a * w + li;
    for (int b = 0; b < 2; ++b) {
      p.add(kTransitionBlocks + 2 * a + b, i, first, w,
            [&](Index lj) { return std::abs(e.transition(row, b * w + lj)); });
    }
    p.add(kRisingBlocks + a, i, first, w,
          [&](Index lj) { return std::abs(e.rising_load(row, lj)); });
    p.add(kFallingBlocks + a, i, first, w,
          [&](Index lj) { return std::abs(e.falling_load(row, lj)); });
  }
}

// All operators with band = margin, their profiles, and the harmonic responses.
struct Assembly {
  BandedMatrix transition, rising, falling;
  std::vector<HarmonicResponse> harmonics;
  Profiles profiles{0, 0};
  Index blocks = 0, exponentials = 0, largest = 0;
};

// The substructures' work (Σ (2w)³ over the window widths w) from which assemble spreads them
// over the threads: about 40 ms on one thread of this machine (1.7 ms for 4.6e5).
constexpr double kSpreadWork = 1e7;

Assembly assemble(const GapStructure& s, double step, const std::vector<LoadGroup>& loads,
                  Index margin, Index cell, const BandedExponentialOptions& o) {
  const Index n = s.dofs();
  const Index R = margin;
  const std::vector<RowBlock> blocks = partition_rows(n, R, cell);

  Assembly out;
  out.profiles = Profiles(kBlockTypes, R);
  out.blocks = static_cast<Index>(blocks.size());
  BandedMatrixBuilder bt(2 * n, 2 * n, 4 * R + 2, o.share_rows);
  BandedMatrixBuilder br(2 * n, n, 2 * R + 1, o.share_rows);
  BandedMatrixBuilder bf(2 * n, n, 2 * R + 1, o.share_rows);
  for (const LoadGroup& g : loads) {
    out.harmonics.push_back({g.omega, Vector::Zero(2 * n), Vector::Zero(2 * n)});
  }
  std::vector<double> row(static_cast<std::size_t>(4 * R + 2));

  const auto scatter = [&](const RowBlock& block, const SubstructureExponential& e) {
    const Index w = e.size, first = block.window_first;
    for (Index i = block.begin; i < block.end; ++i) {
      const Index li = i - first;
      const Index lo = std::max<Index>(0, i - R), hi = std::min(n, i + R + 1);
      const Index span = hi - lo, l0 = lo - first;
      for (int a = 0; a < 2; ++a) {
        const Index r = a * w + li;
        for (Index j = 0; j < span; ++j) {
          row[static_cast<std::size_t>(2 * j)] = e.transition(r, l0 + j);
          row[static_cast<std::size_t>(2 * j + 1)] = e.transition(r, w + l0 + j);
        }
        bt.set_row(2 * i + a, 2 * lo, row.data(), 2 * span);
        for (Index j = 0; j < span; ++j) row[static_cast<std::size_t>(j)] = e.rising_load(r, l0 + j);
        br.set_row(2 * i + a, lo, row.data(), span);
        for (Index j = 0; j < span; ++j) row[static_cast<std::size_t>(j)] = e.falling_load(r, l0 + j);
        bf.set_row(2 * i + a, lo, row.data(), span);
        for (std::size_t g = 0; g < loads.size(); ++g) {
          out.harmonics[g].sin_response[2 * i + a] = e.harmonics[g].sin_response[r];
          out.harmonics[g].cos_response[2 * i + a] = e.harmonics[g].cos_response[r];
        }
      }
      add_profiles(out.profiles, e, first, i);
    }
  };

  // Blocks are taken in chunks: the distinct substructures of a chunk are computed in parallel,
  // then its rows are stored. Only the substructures the current chunk used are kept, so a
  // periodic structure keeps its one interior substructure and a varying one keeps a chunk's.
  struct Entry {
    std::shared_ptr<const SubstructureExponential> e;
    std::size_t chunk;
  };
  std::unordered_map<SubstructureKey, Entry, SubstructureKey::Hasher> cache;
  constexpr std::size_t kChunk = 256;
  std::vector<Entry*> used;
  std::vector<std::pair<Entry*, const RowBlock*>> missing;
  const CellRepeats repeats(s, cell, loads);
  for (std::size_t c0 = 0; c0 < blocks.size(); c0 += kChunk) {
    const std::size_t c1 = std::min(blocks.size(), c0 + kChunk);
    used.clear();
    missing.clear();
    for (std::size_t b = c0; b < c1; ++b) {
      const RowBlock& block = blocks[b];
      const auto back = static_cast<std::size_t>(repeats.shift() / std::max<Index>(cell, 1));
      if (back > 0 && b >= c0 + back && repeats_block(blocks[b - back], block, repeats)) {
        used.push_back(used[b - c0 - back]);  // that block's substructure, `back` cells on
        continue;
      }
      SubstructureKey key(s, block.window_first, block.window_last, loads);
      auto [it, inserted] = cache.try_emplace(std::move(key), Entry{nullptr, c0});
      it->second.chunk = c0;
      if (inserted) missing.emplace_back(&it->second, &block);
      used.push_back(&it->second);
      out.largest = std::max(out.largest, block.window_last - block.window_first);
    }
    std::exception_ptr error;
    // Each exponential's products stay on the thread that computes it (a SerialProducts in the
    // loop's body: inside a team Eigen would not split them anyway, but a nested or inactive
    // region hands its tasks the next entry of an OMP_NUM_THREADS list such as 2,2, and Eigen
    // would split again). Split over the threads, a wide window's products would round their
    // partial sums differently, and a substructure's bits would depend on which other blocks
    // share its chunk (construction from the period relies on them not depending on that). The
    // substructures themselves go over the threads only when there is work enough to pay for a
    // parallel region: after one the idle threads spin before they sleep, about 8 ms of CPU time
    // here, where a periodic chain's few substructures (5 of 22 degrees of freedom on the
    // 1000-mass chain at η = 0.4 s) take 1.7 ms on one thread and 1.6 ms on two. Without that
    // work no region is opened at all.
    double work = 0.0;  // the products' multiply-adds, up to a constant: Σ (2w)³
    for (const auto& [entry, block] : missing) {
      const auto w = static_cast<double>(block->window_last - block->window_first);
      work += 8.0 * w * w * w;
    }
    const auto compute = [&](std::size_t k) {
      const numerics_detail::SerialProducts serial;
      try {
        const RowBlock& block = *missing[k].second;
        missing[k].first->e = std::make_shared<const SubstructureExponential>(
            substructure_exponential(s, block.window_first, block.window_last, step, loads,
                                     o.exponential));
      } catch (...) {
#pragma omp critical
        if (!error) error = std::current_exception();
      }
    };
    if (missing.size() > 1 && work >= kSpreadWork) {
#pragma omp parallel for schedule(dynamic)
      for (std::size_t k = 0; k < missing.size(); ++k) compute(k);
    } else {
      for (std::size_t k = 0; k < missing.size(); ++k) compute(k);
    }
    if (error) std::rethrow_exception(error);
    out.exponentials += static_cast<Index>(missing.size());
    for (std::size_t b = c0; b < c1; ++b) scatter(blocks[b], *used[b - c0]->e);
    std::erase_if(cache, [&](const auto& item) { return item.second.chunk != c0; });
  }
  out.transition = bt.build();
  out.rising = br.build();
  out.falling = bf.build();
  return out;
}

// A first margin from the substructure around the middle row alone (grown until its band fits);
// *reach: how far from the middle row the largest substructure probed reached.
Index probe_margin(const GapStructure& s, double step, const BandedExponentialOptions& o,
                   Index* reach) {
  const Index n = s.dofs();
  const Index mid = n / 2;
  for (Index R = std::max<Index>(4, o.guard + 3);; R *= 2) {
    const Index first = std::max<Index>(0, mid - R), last = std::min(n, mid + R + 1);
    // T alone: the load integrals fall off faster, and the assembly checks them anyway.
    const Index w = last - first, li = mid - first;
    *reach = R;
    const auto serial = numerics_detail::SerialProducts::for_rows(2 * w);
    const Matrix T = precise_exponential(substructure_state_matrix(s, first, last), step,
                                         o.exponential);
    Profiles p(4, R);
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        p.add(2 * a + b, mid, first, w,
              [&](Index lj) { return std::abs(T(a * w + li, b * w + lj)); });
    const Index q = p.band_for(o.tolerance);
    const bool whole = first == 0 && last == n;
    if ((q >= 0 && q + o.guard < R) || whole) return (q >= 0 ? q : R) + o.guard + 1;
    if (R > o.max_band + o.guard) {
      throw InputError(fmt::format(
          "no band up to max_band = {} meets tolerance = {} at step = {} (the energy of one step "
          "travels farther); use a smaller step or a larger max_band",
          o.max_band, o.tolerance, step));
    }
  }
}

// Copies band q out of a band-R operator on the interleaved rows (columns: 2 per degree of
// freedom for T, 1 for the load integrals).
BandedMatrix narrow(const BandedMatrix& A, Index n, Index q, Index per_dof, bool share) {
  BandedMatrixBuilder b(A.rows(), A.cols(), per_dof * (2 * q + 1), share);
  for (Index r = 0; r < A.rows(); ++r) {
    const Index i = r / 2;
    const Index lo = per_dof * std::max<Index>(0, i - q);
    const Index hi = per_dof * std::min(n, i + q + 1);
    const double* v = A.row_values(r) + (lo - A.first_column(r));
    b.set_row(r, lo, v, hi - lo);
  }
  return b.build();
}

bool mass_is_diagonal(const SparseMatrix& M, std::string* why) {
  for (Index j = 0; j < M.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(M, j); it; ++it) {
      if (it.row() != j && it.value() != 0.0) {
        *why = fmt::format("mass[{},{}] = {}: the banded method needs a diagonal (lumped) mass "
                           "matrix",
                           it.row(), j, it.value());
        return false;
      }
    }
  }
  return true;
}

}  // namespace

namespace banded_detail {

void check_banded_inputs(const GapStructure& structure, double step,
                         const BandedExponentialOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("banded exponential options: " + why);
  structure.validate();
  if (!std::isfinite(step) || step <= 0.0) {
    throw InputError(fmt::format("step = {} must be positive and finite", step));
  }
  if (!mass_is_diagonal(structure.mass, &why)) throw InputError(why);
}

}  // namespace banded_detail

BandedExponential make_banded_exponential(const GapStructure& structure, double step,
                                          const BandedExponentialOptions& options) {
  banded_detail::check_banded_inputs(structure, step, options);
  const Index n = structure.dofs();
  const std::vector<LoadGroup> groups = structure.load_groups();
  const Index cell = options.cell_dofs > 0 ? options.cell_dofs : detect_cell_size(structure);

  Index probed = 0;
  Index margin = options.band > 0 ? options.band + options.guard
                                  : probe_margin(structure, step, options, &probed);
  Assembly a;
  Index q = options.band;
  int assemblies = 0;
  for (;;) {
    a = assemble(structure, step, groups, margin, cell, options);
    ++assemblies;
    if (options.band > 0) break;
    q = a.profiles.band_for(options.tolerance);
    const bool whole = margin >= n - 1;
    if (q >= 0 && (q + options.guard <= margin || whole)) break;
    const Index next = q >= 0 ? q + options.guard + 1 : 2 * margin;
    if (next > options.max_band + options.guard) {
      throw InputError(fmt::format(
          "no band up to max_band = {} meets tolerance = {} at step = {}; use a smaller step or a "
          "larger max_band",
          options.max_band, options.tolerance, step));
    }
    margin = next;
  }
  q = std::min(q, margin);

  BandedExponential out;
  out.step = step;
  out.transition = narrow(a.transition, n, q, 2, options.share_rows);
  out.rising_load = narrow(a.rising, n, q, 1, options.share_rows);
  out.falling_load = narrow(a.falling, n, q, 1, options.share_rows);

  out.harmonics = std::move(a.harmonics);

  BandTruncation& t = out.truncation;
  t.tolerance = options.tolerance;
  t.band = q;
  t.margin = margin;
  t.cell_dofs = cell;
  int worst = 0;
  t.dropped_ratio = a.profiles.ratio_at(q, &worst);
  t.worst_block = block_name(worst);
  t.blocks = a.blocks;
  t.exponentials = a.exponentials;
  t.largest_substructure = a.largest;
  t.assemblies = assemblies;
  t.probe_reach = probed;
  return out;
}

}  // namespace pwl
