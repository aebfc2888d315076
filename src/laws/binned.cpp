// SPDX-License-Identifier: GPL-3.0-or-later
#include "asperity/laws/binned.hpp"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/special_functions/erf.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace asperity {

void Moments::merge(const Moments& o) {
  if (o.n == 0) return;
  if (n == 0) {
    *this = o;
    return;
  }
  const double na = double(n), nb = double(o.n), nn = na + nb, d = o.mean - mean;
  mean += d * (nb / nn);
  m2 += o.m2 + d * d * (na * nb / nn);
  n += o.n;
}

Moments ShiftedSums::moments(double c) const {
  Moments m;
  if (n == 0) return m;
  const double nn = double(n), a = s1 / nn;
  m.n = n;
  m.mean = c + a;
  m.m2 = std::max(0.0, s2 - s1 * a);  // >= 0 in exact arithmetic; rounding must not make it negative
  return m;
}

double Reference::mean() const {
  return kind == Kind::rayleigh ? sigma * std::sqrt(std::numbers::pi / 2) : 0.0;
}

double Reference::cdf(double x) const {
  if (kind == Kind::rayleigh) return x <= 0 ? 0.0 : -std::expm1(-x * x / (2 * sigma * sigma));
  return 0.5 * std::erfc(-x / (sigma * std::numbers::sqrt2));
}

double Reference::quantile(double u) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (kind == Kind::rayleigh) return u <= 0 ? 0.0 : u >= 1 ? inf : sigma * std::sqrt(-2.0 * std::log1p(-u));
  if (u <= 0) return -inf;
  if (u >= 1) return inf;
  return -sigma * std::numbers::sqrt2 * boost::math::erfc_inv(2.0 * u);
}

FineBinner::FineBinner(const Reference& ref, unsigned fine_log2) {
  constexpr std::size_t kTable = 8192;  // interpolation error < 2 fine bins even at 2^24 bins
  const std::size_t B = std::size_t{1} << fine_log2;
  edge_.resize(B + 1);
  edge_[0] = -std::numeric_limits<double>::infinity();
  edge_[B] = std::numeric_limits<double>::infinity();
  for (std::size_t j = 1; j < B; ++j) {
    edge_[j] = ref.quantile(double(j) / double(B));
    if (!(edge_[j] >= edge_[j - 1])) throw std::logic_error("FineBinner: reference quantiles are not non-decreasing");
  }
  lo_ = ref.kind == Reference::Kind::rayleigh ? 0.0 : -8.0 * ref.sigma;
  const double h = (8.0 * ref.sigma - lo_) / double(kTable);
  inv_h_ = 1.0 / h;
  tmax_ = std::nextafter(double(kTable), 0.0);
  table_.resize(kTable + 1);
  for (std::size_t i = 0; i <= kTable; ++i) table_[i] = ref.cdf(lo_ + double(i) * h) * double(B);
  last_ = B - 1;
  // The shortcut needs g non-decreasing: the table must be (then g is, up to an ulp of g at a node,
  // << the 1e-6 allowance below for any B <= 2^24), and g(x_j) within slack of j at every edge.
  for (std::size_t i = 1; i <= kTable; ++i)
    if (!(table_[i] >= table_[i - 1])) return;  // slack_ stays 1: always the comparisons
  double worst = 0;
  for (std::size_t j = 1; j < B; ++j) worst = std::max(worst, std::abs(guess(edge_[j]) - double(j)));
  slack_ = std::min(1.0, worst + 1e-6);
}

std::string Reference::name() const {
  std::ostringstream os;
  os << (kind == Kind::rayleigh ? "Rayleigh" : "normal") << "(sigma = " << sigma << ")";
  return os.str();
}

BinnedStats make_binned(const Reference& ref, std::size_t blocks, unsigned fine_log2, unsigned coarse_log2) {
  if (coarse_log2 < 4 || coarse_log2 > 16)
    throw std::invalid_argument("make_binned: coarse_log2 must be in [4, 16], got " + std::to_string(coarse_log2));
  if (fine_log2 < coarse_log2 || fine_log2 > 24)
    throw std::invalid_argument("make_binned: fine_log2 (bins = 2^fine_log2) must be in [" + std::to_string(coarse_log2) +
                                ", 24], got " + std::to_string(fine_log2));
  if (blocks == 0) throw std::invalid_argument("make_binned: blocks must be >= 1");
  if (!(ref.sigma > 0) || !std::isfinite(ref.sigma))
    throw std::invalid_argument("make_binned: reference sigma must be finite and > 0");
  BinnedStats s;
  s.ref = ref, s.fine_log2 = fine_log2, s.coarse_log2 = coarse_log2, s.blocks = blocks;
  s.fine.assign(s.fine_bins(), 0);
  s.coarse.assign(blocks * s.coarse_bins(), 0);
  s.block_moments.assign(blocks, Moments{});
  return s;
}

std::uint64_t BinnedStats::n() const {
  std::uint64_t t = 0;
  for (auto c : fine) t += c;
  return t;
}

std::size_t BinnedStats::fine_bin(double u) const {
  // u 2^k is exact (a power of two); its floor shifted right is the coarse bin: the two agree.
  const double b = std::floor(u * double(fine_bins()));
  if (!(b > 0)) return 0;  // NaN too: never an index out of range
  return b >= double(fine_bins()) ? fine_bins() - 1 : static_cast<std::size_t>(b);
}

Moments BinnedStats::moments() const {
  Moments m;
  for (const auto& b : block_moments) m.merge(b);
  return m;
}

void BinnedStats::merge(const BinnedStats& o) {
  if (o.ref != ref || o.fine_log2 != fine_log2 || o.coarse_log2 != coarse_log2 || o.blocks != blocks)
    throw std::invalid_argument("BinnedStats::merge: the two statistics have different references or layouts");
  for (std::size_t i = 0; i < fine.size(); ++i) fine[i] += o.fine[i];
  for (std::size_t i = 0; i < coarse.size(); ++i) coarse[i] += o.coarse[i];
  for (std::size_t g = 0; g < blocks; ++g) block_moments[g].merge(o.block_moments[g]);
}

double reference_u(const Reference& ref, double x) {
  if (std::isnan(x)) throw std::invalid_argument("reference_u: NaN sample");
  return ref.cdf(x);
}

void add_sample(BinnedStats& s, std::size_t block, double u) {
  const std::size_t f = s.fine_bin(u);
  ++s.fine[f];
  ++s.coarse[block * s.coarse_bins() + (f >> (s.fine_log2 - s.coarse_log2))];
}

namespace {

// F at the edges x_j = ref.quantile(j / bins), j = 0..bins; F(x_0) = 0 and F(x_bins) = 1 exactly
// (the ends of the reference's support hold the whole law: both laws live on the same support).
std::vector<double> cdf_at_edges(const Reference& ref, const Cdf& cdf, std::size_t bins) {
  std::vector<double> F(bins + 1);
  F[0] = 0, F[bins] = 1;
  for (std::size_t j = 1; j < bins; ++j) {
    const double x = ref.quantile(double(j) / double(bins));
    const double f = cdf(x);
    if (!(f >= 0 && f <= 1))
      throw std::invalid_argument("binned test: cdf(" + std::to_string(x) + ") = " + std::to_string(f) + " is not in [0, 1]");
    F[j] = f;
  }
  return F;
}

std::string resolution_text(std::size_t bins) {
  int k = 0;
  while ((std::size_t{1} << k) < bins) ++k;
  return "2^" + std::to_string(k) + " bins of u = F_ref(x), resolution 2^-" + std::to_string(k) + " in u";
}

}  // namespace

BinnedTest binned_ks(const BinnedStats& s, const Cdf& cdf) {
  const std::size_t B = s.fine_bins();
  const auto F = cdf_at_edges(s.ref, cdf, B);
  const std::uint64_t n = s.n();
  BinnedTest t{"binned-KS", 0, 1, n, 1.0 / double(B), ""};
  if (n == 0) throw std::invalid_argument("binned_ks: no samples");
  std::uint64_t cum = 0;
  for (std::size_t j = 1; j < B; ++j) {
    cum += s.fine[j - 1];
    t.value = std::max(t.value, std::abs(double(cum) / double(n) - F[j]));
  }
  t.p = kolmogorov_pvalue(t.value, n);
  t.note = "KS distance on " + resolution_text(B) + ", exact bin probabilities of the law; Kolmogorov p (iid drops; D on a "
           "grid is at most the continuous D)";
  return t;
}

BinnedTest binned_chi2(const BinnedStats& s, const Cdf& cdf, std::size_t cells) {
  const std::size_t B = s.fine_bins();
  cells = std::clamp<std::size_t>(cells, 2, B);
  const std::size_t per = B / cells;
  cells = B / per;
  const auto F = cdf_at_edges(s.ref, cdf, B);
  const std::uint64_t n = s.n();
  if (n == 0) throw std::invalid_argument("binned_chi2: no samples");
  // Cells of `per` fine bins, merged greedily until the expected count reaches 5; a remainder below
  // 5 at the right end joins the last cell.
  std::vector<std::pair<double, double>> oe;  // observed, expected
  double e_acc = 0, o_acc = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    const std::size_t lo = c * per, hi = c + 1 == cells ? B : lo + per;
    for (std::size_t j = lo; j < hi; ++j) o_acc += double(s.fine[j]);
    e_acc += double(n) * (F[hi] - F[lo]);
    if (e_acc >= 5.0) oe.emplace_back(o_acc, e_acc), e_acc = 0, o_acc = 0;
  }
  if (!oe.empty()) oe.back().first += o_acc, oe.back().second += e_acc;
  double chi2 = 0;
  for (const auto& [o, e] : oe) chi2 += (o - e) * (o - e) / e;
  const std::size_t used = oe.size();
  BinnedTest t{"chi2", chi2, std::numeric_limits<double>::quiet_NaN(), n, double(per) / double(B), ""};
  if (used >= 2) t.p = boost::math::cdf(boost::math::complement(boost::math::chi_squared_distribution<double>(double(used - 1)), chi2));
  t.note = "Pearson chi^2 on " + std::to_string(used) + " cells of >= " + std::to_string(per) + " fine bins (" +
           resolution_text(B / per) + "), exact expected counts; chi^2 p with " + std::to_string(used - 1) +
           " dof (iid drops)";
  if (used < 2) t.note = "too few samples for 2 cells of expected count >= 5: no test";
  return t;
}

namespace {

struct LrCells {
  std::vector<std::size_t> group;  // coarse bin -> cell
  std::vector<double> p0, p1, ell; // per cell: probabilities and log(p1/p0)
};

// Coarse bins grouped until both laws give the group a positive probability; the log ratio uses
// log1p of the difference of the laws (computed as F1 - F0 at each edge) to keep its precision.
LrCells lr_cells(const BinnedStats& s, const Cdf& law0, const Cdf& law1) {
  const std::size_t C = s.coarse_bins();
  const auto F0 = cdf_at_edges(s.ref, law0, C), F1 = cdf_at_edges(s.ref, law1, C);
  LrCells c;
  c.group.assign(C, 0);
  std::size_t start = 0;
  for (std::size_t j = 0; j < C; ++j) {
    const double p0 = F0[j + 1] - F0[start], p1 = F1[j + 1] - F1[start];
    c.group[j] = c.p0.size();
    if ((p0 > 0 && p1 > 0) || j + 1 == C) {
      const double delta = (F1[j + 1] - F0[j + 1]) - (F1[start] - F0[start]);
      if (p0 > 0 && p1 > 0) {
        c.p0.push_back(p0), c.p1.push_back(p1), c.ell.push_back(std::log1p(delta / p0));
      } else if (!c.p0.empty()) {  // an empty tail joins the last cell (the laws give it nothing)
        for (std::size_t i = start; i <= j; ++i) c.group[i] = c.p0.size() - 1;
      } else {
        throw std::invalid_argument("binned_lr: the two laws share no cell of positive probability");
      }
      start = j + 1;
    }
  }
  return c;
}

}  // namespace

LrTest binned_lr(const BinnedStats& s, const Cdf& law0, const Cdf& law1) {
  const LrCells c = lr_cells(s, law0, law1);
  LrTest r;
  for (std::size_t i = 0; i < c.ell.size(); ++i) r.kl01 -= c.p0[i] * c.ell[i], r.kl10 += c.p1[i] * c.ell[i];
  const std::size_t C = s.coarse_bins();
  std::vector<double> Lg, mg;
  for (std::size_t g = 0; g < s.blocks; ++g) {
    double L = 0, m = 0;
    for (std::size_t j = 0; j < C; ++j) {
      const double k = double(s.coarse[g * C + j]);
      L += k * c.ell[c.group[j]], m += k;
    }
    if (m > 0) Lg.push_back(L), mg.push_back(m);
  }
  const std::size_t G = Lg.size();
  r.blocks = G;
  if (G < 2) throw std::invalid_argument("binned_lr: needs >= 2 blocks with samples, got " + std::to_string(G));
  double Lsum = 0, n = 0;
  for (std::size_t g = 0; g < G; ++g) Lsum += Lg[g], n += mg[g];
  r.L = Lsum / n;
  double ss = 0;
  for (std::size_t g = 0; g < G; ++g) ss += (Lg[g] - r.L * mg[g]) * (Lg[g] - r.L * mg[g]);
  r.se = std::sqrt(double(G) / double(G - 1) * ss) / n;
  boost::math::students_t_distribution<double> t(double(G - 1));
  const double z0 = (r.L + r.kl01) / r.se, z1 = (r.L - r.kl10) / r.se;
  const std::string res = resolution_text(C);
  const std::string how = "per-drop log likelihood ratio on " + res + ", se from the spread between " +
                          std::to_string(G) + " blocks of whole spheres; one-sided Student t p (" +
                          std::to_string(G - 1) + " dof)";
  const auto n_u = static_cast<std::uint64_t>(n);
  r.law0 = {"LR-block", z0, boost::math::cdf(boost::math::complement(t, z0)), n_u, 1.0 / double(C),
            how + "; rejects this law when the data lean to the other"};
  r.law1 = {"LR-block", z1, boost::math::cdf(t, z1), n_u, 1.0 / double(C),
            how + "; rejects this law when the data lean to the other"};
  return r;
}

BlockBins to_block_bins(const BinnedStats& s) {
  const std::size_t C = s.coarse_bins();
  BlockBins b;
  for (std::size_t j = 1; j < C; ++j) b.edges.push_back(s.ref.quantile(double(j) / double(C)));
  b.blocks = s.blocks;
  b.counts.resize(s.coarse.size());
  b.block_size.assign(s.blocks, 0);
  for (std::size_t i = 0; i < s.coarse.size(); ++i) {
    if (s.coarse[i] > std::numeric_limits<std::uint32_t>::max())
      throw std::overflow_error("to_block_bins: a block's bin holds more than 2^32 - 1 samples");
    b.counts[i] = static_cast<std::uint32_t>(s.coarse[i]);
    b.block_size[i / C] += s.coarse[i];
  }
  b.n = static_cast<std::size_t>(s.n());
  std::vector<std::uint64_t> total(C, 0);
  for (std::size_t i = 0; i < s.coarse.size(); ++i) total[i % C] += s.coarse[i];
  std::uint64_t cum = 0;
  for (std::size_t j = 0; j + 1 < C; ++j) b.pooled.push_back(double(cum += total[j]) / double(b.n));
  return b;
}

CdfBand pooled_cdf(const BinnedStats& s) {
  const std::size_t C = s.coarse_bins(), G = s.blocks;
  CdfBand band;
  const double n = double(s.n());
  std::vector<double> cum(G, 0), size(G, 0);
  for (std::size_t g = 0; g < G; ++g)
    for (std::size_t j = 0; j < C; ++j) size[g] += double(s.coarse[g * C + j]);
  std::size_t used = 0;
  for (double m : size) used += m > 0;
  for (std::size_t j = 0; j + 1 < C; ++j) {
    double total = 0;
    for (std::size_t g = 0; g < G; ++g) total += (cum[g] += double(s.coarse[g * C + j]));
    const double F = total / n;
    double ss = 0;
    for (std::size_t g = 0; g < G; ++g)
      if (size[g] > 0) ss += (cum[g] - F * size[g]) * (cum[g] - F * size[g]);
    band.x.push_back(s.ref.quantile(double(j + 1) / double(C)));
    band.cdf.push_back(F);
    band.se.push_back(used > 1 ? std::sqrt(double(used) / double(used - 1) * ss) / n
                               : std::numeric_limits<double>::quiet_NaN());
  }
  return band;
}

double lr_sample_size(const Reference& ref, const Cdf& law0, const Cdf& law1, double alpha, double beta,
                      unsigned cells_log2) {
  const BinnedStats empty = make_binned(ref, 1, cells_log2, cells_log2);
  const LrCells c = lr_cells(empty, law0, law1);
  double kl01 = 0, kl10 = 0, m2 = 0;
  for (std::size_t i = 0; i < c.ell.size(); ++i)
    kl01 -= c.p0[i] * c.ell[i], kl10 += c.p1[i] * c.ell[i], m2 += c.p1[i] * c.ell[i] * c.ell[i];
  const double sd = std::sqrt(std::max(0.0, m2 - kl10 * kl10));
  boost::math::normal z;
  const double zz = boost::math::quantile(z, 1 - alpha) + boost::math::quantile(z, 1 - beta);
  return std::pow(zz * sd / (kl01 + kl10), 2);
}

}  // namespace asperity
