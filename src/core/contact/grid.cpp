// SPDX-License-Identifier: GPL-3.0-or-later
// Cube-map grid backend: the unit centres are bucketed on the six faces of a cube (gnomonic
// projection) and a query scans a rectangle of cells around the down direction, growing it until
// an exact lower bound on the key of every point outside the rectangle exceeds the runner-up key.
//
// Layout. Face f = 2a + (negative), a = 0,1,2 the axis: e3 = +-E_a (outward), e1 = E_b, e2 = E_c
// with b = a+1, c = a+2 (mod 3). A unit p with p3 = p.e3 > 0 has gnomonic coordinates
// s = p_b / p3, t = p_c / p3. Each face covers the EXTENDED square [-S, S]^2, S = 1 + margin, so
// points near a cube edge are stored in two or three faces, and every query, whose direction d has
// |s|, |t| <= 1 on the face of its largest component, finds its neighbourhood on that one face. The
// cell edges E_0 = -S < E_1 < ... < E_G = S are equally spaced in ANGLE (E_k = tan(alpha_k)), so
// cells hold about the same number of points everywhere; the cell k of a coordinate s is DEFINED by
// the exact comparisons E_k <= s < E_(k+1) (a lookup table only guesses k). Cells are numbered
// face-major, then t row, then s column, in one CSR array: cs_ (cell starts) and 32-byte records of
// x, y, z (bit-exact copies of the input) and the original index (one record per point: a run of
// points is one stretch of memory). Within a cell points are in index order, so the structure does
// not depend on the thread count.
//
// Query. The 3x3 cells around d's cell are three contiguous runs of points (one per row). The fast
// path reads each run's blocks of four records (up to kRowSlots points; slots past the run's end get
// an infinite key), computes all keys with (target-cloned) vector arithmetic -- the same
// IEEE operations in the same order as asperity::contact_key, hence the same bits -- and reduces
// them to the canonical top two (the two smallest (key, index) pairs, which is what TopTwo keeps
// when, as on one face, no index repeats; an exact tie for the lowest key is left to TopTwo
// below). Runs longer than kRowSlots, exact key ties, windows at the face
// border and failed bounds go to the general path (grow), which offers points to detail::TopTwo and
// moves the limiting window edge out by one row or column at a time.
//
// Exactness. A window of cells [i0, i1] x [j0, j1] corresponds to the cone bounded by the four
// planes through the origin containing the edge lines s = E_i0, s = E_(i1+1), t = E_j0, t = E_(j1+1)
// (normal of s = e: (e1 - e e3) / sqrt(1 + e^2)), plus the plane p3 = 0 (without it, the four
// half-spaces also contain the antipodal cone). A point that was not scanned is either outside the
// face (p3 <= 0) or has a computed coordinate outside the window, hence a true coordinate beyond the
// window edge moved inward by kSlack (p_b * (1 / p3) errs by < 1e-15 for the coordinates that
// matter). Such a point lies on the far side of one of the five planes, while d lies on the near
// side at angular distance asin(y) from it, y = n.d; so the point's angle from d is >= asin(y) and
// its key is >= 2 - 2 sqrt(1 - y^2), which is > K iff y^2 > K - K^2/4 (for K < 2). We stop when,
// with K = runner-up key * (1 + 1e-9) < 1 and y computed conservatively (absolute slack 2 kSlack,
// relative 1e-9), the smallest y^2 of the five planes exceeds K - K^2/4: every unscanned point then
// has a key strictly above the runner-up, so it can neither be the answer nor tie with it. Rounding
// of y, of the keys and the non-unit length of the inputs (| |v|^2 - 1 | <= 1e-12, checked;
// otherwise brute force) are many orders of magnitude below these margins. When the plane limiting
// the bound cannot be moved (the extended-face border or p3 = 0), nothing scanned later on this face
// could meet the criterion, and the query falls back to the reference scan brute_lowest, which is
// the answer by definition. Single and batched queries run the same search; the batch only adds
// prefetches.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <numbers>
#include <stdexcept>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "core/contact/detail.hpp"

// The fast-path kernel uses GCC vector extensions; other compilers take the general path only.
#if defined(__GNUC__) && !defined(__clang__)
#define ASPERITY_GRID_FAST 1
#else
#define ASPERITY_GRID_FAST 0
#endif
// Function multi-versioning of the kernel (x86-64 Linux: resolved once, by ifunc).
#if ASPERITY_GRID_FAST && defined(__x86_64__) && defined(__linux__)
#define ASPERITY_GRID_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define ASPERITY_GRID_CLONES
#endif

namespace asperity::detail {


namespace {

constexpr double kSlack = 1e-11;    // inward shift of the window edges (gnomonic units)
constexpr double kRel = 1e-9;       // relative safety of the stopping bound
constexpr double kUnitTol = 1e-12;  // | |v|^2 - 1 | accepted as a unit vector
[[maybe_unused]] constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// Fast path: slots read per run of three cells (a multiple of 4), and the mean number of points
// per cell. With these, ~8% of random queries fail the 3x3 bound and ~3% have a longer run; both
// then take the general path. Measured best among kRowSlots 8/12/16 x kPerCell 1.0..2.5.
constexpr int kRowSlots = 8;
constexpr double kPerCell = 1.3;
constexpr std::size_t kPad = kRowSlots + 4;  // readable slots past the last point (records and float rows)
static_assert(kRowSlots == 8, "window_winner reads one 8-lane float vector per run");
constexpr std::size_t kResidentBytes = std::size_t{1} << 20;  // batched queries without prefetch up to this

/// Allocator for the big arrays: 2 MiB-aligned and, on Linux, backed by transparent huge pages
/// when available, so that the random accesses of the queries do not miss the TLB each time.
/// On Linux they are mapped directly and unmapped when freed: from the heap (aligned_alloc, with
/// validate-geometry's mallopt keeping freed memory up to 512 MB) each sphere's 2 MiB-aligned
/// arrays fragmented it, so K spheres of N = 1e6 held ~12-25 MB more per sphere (232 MB at K = 10
/// against 119 MB at K = 2, --threads 1; issue 43's memory survey).
// Under AddressSanitizer the arrays stay heap blocks: ASan puts redzones around those, not around a
// mapping, and the sanitized tests are there to catch an out-of-bounds index.
#if defined(__SANITIZE_ADDRESS__)
#define ASPERITY_GRID_MMAP 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ASPERITY_GRID_MMAP 0
#endif
#endif
#if !defined(ASPERITY_GRID_MMAP)
#if defined(__linux__) && defined(MAP_ANONYMOUS)
#define ASPERITY_GRID_MMAP 1
#else
#define ASPERITY_GRID_MMAP 0
#endif
#endif
template <class T>
struct HugeAlloc {
  using value_type = T;
  HugeAlloc() = default;
  template <class U>
  HugeAlloc(const HugeAlloc<U>&) noexcept {}
  static constexpr std::size_t kHuge = std::size_t{2} << 20;
  static std::size_t rounded(std::size_t n) { return (n * sizeof(T) + kHuge - 1) / kHuge * kHuge; }
  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T) - kHuge) throw std::bad_alloc();
    if (n * sizeof(T) < kHuge) return std::allocator<T>().allocate(n);
    const std::size_t bytes = rounded(n);
#if ASPERITY_GRID_MMAP
    // Over-map by one huge page, keep the 2 MiB-aligned part, return the slack at both ends.
    void* m = mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    const auto base = reinterpret_cast<std::uintptr_t>(m);
    const std::uintptr_t aligned = (base + kHuge - 1) / kHuge * kHuge;
    if (aligned > base) munmap(m, aligned - base);
    if (const std::uintptr_t end = base + bytes + kHuge; end > aligned + bytes)
      munmap(reinterpret_cast<void*>(aligned + bytes), end - (aligned + bytes));
    void* p = reinterpret_cast<void*>(aligned);
#if defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
#else
    void* p = std::aligned_alloc(kHuge, bytes);
    if (!p) throw std::bad_alloc();
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHuge) return std::allocator<T>().deallocate(p, n);
#if ASPERITY_GRID_MMAP
    munmap(p, rounded(n));
#else
    std::free(p);
#endif
  }
  template <class U>
  bool operator==(const HugeAlloc<U>&) const noexcept { return true; }
};
template <class T>
using Array = std::vector<T, HugeAlloc<T>>;

/// A prefetch the optimiser keeps (GCC deletes loops whose only statements are __builtin_prefetch).
inline void prefetch(const void* p) noexcept {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm volatile("prefetcht0 (%0)" : : "r"(p));
#else
  __builtin_prefetch(p);
#endif
}

inline bool is_unit(double x, double y, double z) noexcept {
  const double n2 = x * x + y * y + z * z;
  return std::abs(n2 - 1.0) <= kUnitTol;  // false for NaN
}

// ---- fast-path kernel ---------------------------------------------------------------------------

/// One stored point: its coordinates (bit-exact copies of the input) and original index in one
/// 32-byte record, so a run of points is one contiguous stretch of memory (~2-3 cache lines for
/// the ~4 points of a 3-cell row) instead of four arrays' worth.
struct alignas(32) Pt {
  double x, y, z;
  std::uint32_t id, pad;
};
static_assert(sizeof(Pt) == 32);

struct Runs {
  std::uint32_t begin[3];
  std::uint32_t size[3];  // each <= kRowSlots, total >= 2
};

struct TopPair {
  double k1, k2;
  std::uint32_t i1, i2;
  bool ok;  // false: the two smallest keys tie (then the canonical indices need the general path)
};

#if ASPERITY_GRID_FAST
// 32-byte GCC vector types (lowered to SSE2 pairs in the default clone). They never cross a
// non-inline function boundary, so the ABI note -Wpsabi emits for them does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
using v4d = double __attribute__((vector_size(32)));
using v4l = long long __attribute__((vector_size(32)));

template <class V, class T>
inline V loadu(const T* p) noexcept {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// The keys and ids of the 3 x kRowSlots slots of a window's three runs, INF / kNone past each
/// run's end. Key arithmetic: ((x-dx)^2 + (y-dy)^2) + (z-dz)^2, lane by lane, exactly
/// contact_key's. Reads blocks of four records (transposed to x, y, z, id lanes) only while the
/// run has points in them, so no cache line beyond the run's last block is touched. Inlined into
/// each ISA clone of its callers (top_pair, window_min64).
constexpr int kWindowBlocks = 3 * (kRowSlots / 4);
[[gnu::always_inline]] inline void window_keys(const Pt* pts, const Runs& runs, double dx, double dy, double dz,
                                               v4d (&key)[kWindowBlocks], v4l (&ids)[kWindowBlocks]) noexcept {
  constexpr int kB = kRowSlots / 4;  // blocks of four slots per run
  const v4d DX = {dx, dx, dx, dx}, DY = {dy, dy, dy, dy}, DZ = {dz, dz, dz, dz};
  const v4d INF = {kInf, kInf, kInf, kInf};
  const long long none = kNone;
  for (int r = 0; r < 3; ++r) {
    const long long n = runs.size[r];
    const v4l size = {n, n, n, n};
    for (int q = 0; q < kB; ++q) {
      if (4 * q >= n) {
        key[r * kB + q] = INF;
        ids[r * kB + q] = v4l{none, none, none, none};
        continue;
      }
      const Pt* p = pts + runs.begin[r] + 4u * static_cast<unsigned>(q);
      const v4d p0 = loadu<v4d>(p), p1 = loadu<v4d>(p + 1), p2 = loadu<v4d>(p + 2), p3 = loadu<v4d>(p + 3);
      const v4d t0 = __builtin_shuffle(p0, p1, v4l{0, 4, 2, 6}), t1 = __builtin_shuffle(p0, p1, v4l{1, 5, 3, 7});
      const v4d t2 = __builtin_shuffle(p2, p3, v4l{0, 4, 2, 6}), t3 = __builtin_shuffle(p2, p3, v4l{1, 5, 3, 7});
      const v4d x = __builtin_shuffle(t0, t2, v4l{0, 1, 4, 5}) - DX, y = __builtin_shuffle(t1, t3, v4l{0, 1, 4, 5}) - DY;
      const v4d z = __builtin_shuffle(t0, t2, v4l{2, 3, 6, 7}) - DZ;
      // The id word (id, pad = 0) read as one 64-bit integer is the id.
      const v4l id = reinterpret_cast<v4l>(__builtin_shuffle(t1, t3, v4l{2, 3, 6, 7}));
      const v4d k = (x * x + y * y) + z * z;
      const v4l slot = v4l{0, 1, 2, 3} + 4 * q;
      key[r * kB + q] = slot < size ? k : INF;
      ids[r * kB + q] = slot < size ? id : v4l{none, none, none, none};
    }
  }
}

/// The two smallest keys over the three runs and their indices, when the keys differ.
ASPERITY_GRID_CLONES
TopPair top_pair(const Pt* pts, const Runs& runs, double dx, double dy, double dz) noexcept {
  constexpr int kB = kRowSlots / 4;
  const v4d INF = {kInf, kInf, kInf, kInf};
  const long long none = kNone;
  v4d key[kWindowBlocks];
  v4l ids[kWindowBlocks];
  window_keys(pts, runs, dx, dy, dz, key, ids);
  // The two smallest values with multiplicity, per lane (a1 <= a2), then across lanes.
  v4d a1 = INF, a2 = INF;
  for (int q = 0; q < 3 * kB; ++q) {
    const v4d v = key[q];
    const v4d hi = a1 > v ? a1 : v;
    a2 = hi < a2 ? hi : a2;
    a1 = v < a1 ? v : a1;
  }
  // Merge the lanes pairwise (halves, then neighbours): afterwards every lane holds (m1, m2).
  for (const v4l swap : {v4l{2, 3, 0, 1}, v4l{1, 0, 3, 2}}) {
    const v4d b1 = __builtin_shuffle(a1, swap), b2 = __builtin_shuffle(a2, swap);
    const v4d hi = a1 > b1 ? a1 : b1, lo2 = a2 < b2 ? a2 : b2;
    a2 = hi < lo2 ? hi : lo2;
    a1 = b1 < a1 ? b1 : a1;
  }
  const double m1 = a1[0], m2 = a2[0];
  if (!(m1 < m2)) return {m1, m2, kNone, kNone, false};
  // m1 < m2: exactly one key equals m1; the lowest index among the keys equal to m2.
  v4l e1 = {none, none, none, none}, e2 = e1;
  for (int q = 0; q < 3 * kB; ++q) {
    const v4l idx = ids[q];
    const v4d v = key[q];
    e1 = ((v == a1) & (idx < e1)) ? idx : e1;
    e2 = ((v == a2) & (idx < e2)) ? idx : e2;
  }
  for (const v4l swap : {v4l{2, 3, 0, 1}, v4l{1, 0, 3, 2}}) {
    const v4l f1 = __builtin_shuffle(e1, swap), f2 = __builtin_shuffle(e2, swap);
    e1 = f1 < e1 ? f1 : e1;
    e2 = f2 < e2 ? f2 : e2;
  }
  return {m1, m2, static_cast<std::uint32_t>(e1[0]), static_cast<std::uint32_t>(e2[0]), true};
}

// ---- winner-only kernel (lowest_winners) --------------------------------------------------------
// The 3x3 window's winner from float32 copies of the coordinates (SoA rows: one 8-lane vector per
// run of three cells), with every candidate that could be the FP64 winner rechecked in FP64 by
// contact_key's expression. Float error bound (u = 2^-24, inputs |p_i|, |d_i| <= 1 + 1e-12): the
// float coordinates err by <= u |p_i| each, the float difference by another u, so the float vector
// delta' differs from the true delta by <= sqrt(3) (2u + 2u^2) + u |delta| (Euclidean), and the float
// sum of squares is |delta'|^2 (1 + eta), |eta| <= 3u / (1 - 3u) (underflow adds < 2^-147). Hence a
// point of float key m has true distance <= (sqrt(m) (1 + 4u) + 4u) and the true winner, no farther
// than that point, has float key <= ((1 + 4u) true distance + 4u)^2 (1 + 4u). Candidates: float key
// <= T(m) = ((1 + 1e-6) sqrt(m) + 8u)^2 (1 + 1e-6), which is above that (the FP64 keys differ from
// the true ones by ~1e-16 relative), so every point whose FP64 key equals the window's smallest is
// rechecked, and ties go to the lowest index as in brute_lowest.
using v8f = float __attribute__((vector_size(32)));
using v8i = std::int32_t __attribute__((vector_size(32)));

struct Win {
  double key;
  std::uint32_t id;
};

/// The threshold T(m) above (double, then rounded up to a float by the extra 1e-6).
inline float candidate_bound(float m) noexcept {
  constexpr double u8 = 8.0 * 0x1p-24;
  const double r = (1.0 + 1e-6) * __builtin_sqrt(static_cast<double>(m)) + u8;
  return static_cast<float>(r * r * (1.0 + 2e-6));
}

/// The candidates of the window (float key <= T(m)) as one 24-bit mask: run r in bits 8r .. 8r + 7.
[[gnu::always_inline]] inline std::uint32_t float_candidates(const float* fx, const float* fy, const float* fz,
                                                             const Runs& runs, double dx, double dy, double dz) noexcept {
  const float fdx = static_cast<float>(dx), fdy = static_cast<float>(dy), fdz = static_cast<float>(dz);
  const v8f INF = v8f{} + std::numeric_limits<float>::infinity();
  const v8i lane = {0, 1, 2, 3, 4, 5, 6, 7};
  v8f key[3];
  v8f mn = INF;
  for (int r = 0; r < 3; ++r) {
    const std::uint32_t b = runs.begin[r];
    const v8f x = loadu<v8f>(fx + b) - fdx, y = loadu<v8f>(fy + b) - fdy, z = loadu<v8f>(fz + b) - fdz;
    const v8f k = (x * x + y * y) + z * z;
    key[r] = lane < static_cast<std::int32_t>(runs.size[r]) ? k : INF;
    mn = key[r] < mn ? key[r] : mn;
  }
  for (const v8i swap : {v8i{4, 5, 6, 7, 0, 1, 2, 3}, v8i{2, 3, 0, 1, 6, 7, 4, 5}, v8i{1, 0, 3, 2, 5, 4, 7, 6}}) {
    const v8f o = __builtin_shuffle(mn, swap);
    mn = o < mn ? o : mn;
  }
  const float T = candidate_bound(mn[0]);
  const v8i bit = v8i{1, 2, 4, 8, 16, 32, 64, 128};
  v8i m = ((key[0] <= T) & bit) | ((key[1] <= T) & (bit << 8)) | ((key[2] <= T) & (bit << 16));
  m |= __builtin_shuffle(m, v8i{4, 5, 6, 7, 0, 1, 2, 3});
  m |= __builtin_shuffle(m, v8i{2, 3, 0, 1, 6, 7, 4, 5});
  m |= __builtin_shuffle(m, v8i{1, 0, 3, 2, 5, 4, 7, 6});
  return static_cast<std::uint32_t>(m[0]);
}

/// The FP64 recheck of the candidates `bits` (float_candidates): contact_key's expression, ties
/// to the lowest index.
[[gnu::always_inline]] inline Win recheck(const Pt* pts, const Runs& runs, std::uint32_t bits, double dx, double dy,
                                          double dz) noexcept {
  Win w{kInf, kNone};
  while (bits) {
    const int t = __builtin_ctz(bits);
    bits &= bits - 1;
    const Pt& p = pts[runs.begin[t >> 3] + static_cast<std::uint32_t>(t & 7)];
    const double x = p.x - dx, y = p.y - dy, z = p.z - dz;
    const double k = x * x + y * y + z * z;  // contact_key's expression
    if (key_less(k, p.id, w.key, w.id)) w = Win{k, p.id};
  }
  return w;
}

ASPERITY_GRID_CLONES
Win window_winner(const float* fx, const float* fy, const float* fz, const Pt* pts, const Runs& runs, double dx, double dy,
                  double dz) noexcept {
  return recheck(pts, runs, float_candidates(fx, fy, fz, runs, dx, dy, dz), dx, dy, dz);
}

/// The window's winner from the FP64 records (contact_key's expression, ties to the lowest index),
/// top_pair's arithmetic for the smallest key alone: the batch pipeline's kernel above L2, where a
/// run's records (32 bytes each, ~2-3 cache lines per run) are fewer lines than its three float rows
/// (one or two lines each) plus the rechecked record, and the memory system, not the arithmetic,
/// sets the cost. Runs of <= kRowSlots points.
ASPERITY_GRID_CLONES
Win window_min64(const Pt* pts, const Runs& runs, double dx, double dy, double dz) noexcept {
  constexpr int kB = kRowSlots / 4;
  const v4d INF = {kInf, kInf, kInf, kInf};
  const long long none = kNone;
  v4d key[kWindowBlocks];
  v4l ids[kWindowBlocks];
  window_keys(pts, runs, dx, dy, dz, key, ids);
  v4d a1 = INF;
  for (int q = 0; q < 3 * kB; ++q) a1 = key[q] < a1 ? key[q] : a1;
  for (const v4l swap : {v4l{2, 3, 0, 1}, v4l{1, 0, 3, 2}}) {
    const v4d b1 = __builtin_shuffle(a1, swap);
    a1 = b1 < a1 ? b1 : a1;
  }
  // The lowest index among the keys equal to the smallest (every lane of a1 holds it).
  v4l e1 = {none, none, none, none};
  for (int q = 0; q < 3 * kB; ++q) e1 = ((key[q] == a1) & (ids[q] < e1)) ? ids[q] : e1;
  for (const v4l swap : {v4l{2, 3, 0, 1}, v4l{1, 0, 3, 2}}) {
    const v4l f1 = __builtin_shuffle(e1, swap);
    e1 = f1 < e1 ? f1 : e1;
  }
  return Win{a1[0], static_cast<std::uint32_t>(e1[0])};
}

#endif  // ASPERITY_GRID_FAST

// ---- the grid -----------------------------------------------------------------------------------

/// Where a query direction falls: its face, its cell and its face-frame components.
struct Loc {
  std::uint32_t base = 0;  // first cell of the face
  int i = 0, j = 0;        // s column, t row
  double db = 0, dc = 0, d3 = 0;
  bool brute = true;
};

class Grid;
ASPERITY_GRID_CLONES void resident_winners(const Grid& g, std::span<const Vec3> d, std::span<Nearest> out);

class Grid final : public ContactQuery {
  friend void resident_winners(const Grid& g, std::span<const Vec3> d, std::span<Nearest> out);

 public:
  Grid(std::span<const Vec3> c, int side, double margin) : c_(c) {
    const std::size_t n = c.size();
    if (n >= kNone) throw std::length_error("grid backend: more than 2^32 - 2 centres");
    // Every centre must be a unit vector for the bound to hold; otherwise answer by brute force.
    bool unit = true;
    const auto sn = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) reduction(&& : unit)
    for (std::int64_t i = 0; i < sn; ++i) {
      const Vec3& p = c[static_cast<std::size_t>(i)];
      unit = unit && is_unit(p.x(), p.y(), p.z());
    }
    if (!unit) return;  // brute_ stays true
    brute_ = false;
    if (margin <= 0) {
      // Several runner-up distances (~sqrt(8/N) rad; gnomonic distances near an edge are ~2x).
      margin = std::clamp(12.0 * std::sqrt(8.0 / static_cast<double>(n)), 0.03, 1.0);
    }
    if (side <= 0) {
      // About kPerCell points per cell: a cell spans ~2 atan(S) / G radians each way.
      side = static_cast<int>(std::ceil(2.0 * std::atan(1.0 + margin) *
                                        std::sqrt(static_cast<double>(n) / (4.0 * std::numbers::pi * kPerCell))));
    }
    G_ = std::clamp(side, 1, 4096);
    make_edges(1.0 + margin);
    build();
  }

  Backend backend() const override { return Backend::grid; }

  Nearest lowest(const Vec3& d) const override {
    const Loc L = locate(d);
    if (L.brute) return brute_lowest(c_, d);
    return search(L, d);
  }

  void lowest(std::span<const Vec3> d, std::span<Nearest> out) const override {
    if (out.size() != d.size()) throw std::invalid_argument("lowest(): output size differs from input size");
    batch(d, out, [this](const Loc& L, const Vec3& x) { return L.brute ? brute_lowest(c_, x) : search(L, x); });
  }

  void lowest_winners(std::span<const Vec3> d, std::span<Nearest> out) const override {
    if (out.size() != d.size()) throw std::invalid_argument("lowest_winners(): output size differs from input size");
    if (memory_bytes() <= kResidentBytes) return resident_winners(*this, d, out);
    batch_winners(d, out);
  }

  std::size_t memory_bytes() const override {
    return sizeof(*this) + cs_.capacity() * sizeof(std::uint32_t) + pts_.capacity() * sizeof(Pt) +
           (edge_.capacity() + invn_.capacity() + guard_.capacity()) * sizeof(double) +
           guess_.capacity() * sizeof(std::int32_t) + 3 * fx_.capacity() * sizeof(float);
  }

 private:
  /// Answers a batch by `answer(loc, d)` (the full path).
  template <class Answer>
  void batch(std::span<const Vec3> d, std::span<Nearest> out, Answer answer) const {
    // An index that fits in a core's L2 is answered query by query: the pipeline's prefetches
    // then only cost instructions (N = 10^4: -8% CPU per drop; at N = 3x10^4, 1.6 MB, they pay).
    if (memory_bytes() <= kResidentBytes) {
      for (std::size_t q = 0; q < d.size(); ++q) {
        out[q] = answer(locate(d[q]), d[q]);
      }
      return;
    }
    // Software pipeline: query q is located (and its cell starts prefetched) at step q, its points
    // are prefetched at step q + kLag, and it is searched at step q + 2 kLag.
    constexpr std::size_t kLag = 8, kRing = 32;  // >= 2 kLag + 1; a power of two: % is a mask
    std::array<Loc, kRing> loc;
    const std::size_t n = d.size();
    for (std::size_t step = 0; step < n + 2 * kLag; ++step) {
      if (step < n) {
        Loc& L = loc[step % kRing];
        L = locate(d[step]);
        if (!L.brute) prefetch_starts(L);
      }
      if (step >= kLag && step - kLag < n) {
        const Loc& L = loc[(step - kLag) % kRing];
        if (!L.brute) prefetch_points(L);
      }
      if (step >= 2 * kLag) {
        const std::size_t q = step - 2 * kLag;
        const Loc& L = loc[q % kRing];
        out[q] = answer(L, d[q]);
      }
    }
  }

  /// One query of the winner pipeline: where it falls and its 3x3 runs.
  struct WinSlot {
    Loc L;
    Runs runs;
    std::uint32_t cell = 0;  // j G + i: its guard
    bool fast = false;       // window_min64 answers it (guard > 0, runs of <= kRowSlots)
  };

  /// lowest_winners above L2: a three-stage software pipeline over the batch. (A cell-order sweep
  /// of each batch -- locate all, sort by cell, answer in that order -- measured slower at N = 10^6
  /// with the drop loop's batches of 256: 389-438 against 325-373 ns per query; bench/RESULTS.md.)
  /// Query q is located at step q (its cell starts and its guard
  /// prefetched); at q + kLag its runs are read and every cache line of their FP64 records
  /// prefetched; at q + 2 kLag the window's winner is computed from the records (window_min64, no
  /// float rows: at N >= 10^5 the memory system sets the cost, and the records are the fewest lines)
  /// and certified by the guard or the plane bound, else the full search answers. The winner is
  /// winner()'s: the smallest FP64 key of the window, ties to the lowest index.
  void batch_winners(std::span<const Vec3> d, std::span<Nearest> out) const {
    constexpr std::size_t kLag = 8, kRing = 32;  // >= 2 kLag + 1; a power of two: % is a mask
    std::array<WinSlot, kRing> ring;
    const std::size_t n = d.size();
    const int G = G_;
    for (std::size_t step = 0; step < n + 2 * kLag; ++step) {
      if (step < n) {
        WinSlot& S = ring[step % kRing];
        S.L = locate(d[step]);
        S.fast = false;
        if (!S.L.brute) {
          S.cell = static_cast<std::uint32_t>(S.L.j * G + S.L.i);
          prefetch_starts(S.L);
          prefetch(guard_.data() + S.cell);
        }
      }
      if (step >= kLag && step - kLag < n) {
        WinSlot& S = ring[(step - kLag) % kRing];
        if (!S.L.brute) prefetch_runs(S);
      }
      if (step >= 2 * kLag) {
        const std::size_t q = step - 2 * kLag;
        const WinSlot& S = ring[q % kRing];
        out[q] = S.fast ? finish(S, d[q]) : winner(S.L, d[q]);
      }
    }
  }

  /// Stage two of batch_winners: the runs of S (S.fast: window_min64 can answer) and a prefetch
  /// of every cache line of their records.
  void prefetch_runs(WinSlot& S) const noexcept {
#if ASPERITY_GRID_FAST
    const Loc& L = S.L;
    const int G = G_;
    if (!(guard_[S.cell] > 0)) return;  // 0 at the face border: winner() decides
    const std::uint32_t* cs = cs_.data() + L.base + (L.j - 1) * G + (L.i - 1);
    std::uint32_t big = 0, total = 0;
    for (int r = 0; r < 3; ++r) {
      const std::uint32_t b = cs[r * G], sz = cs[r * G + 3] - b;
      S.runs.begin[r] = b, S.runs.size[r] = sz;
      big |= sz > static_cast<std::uint32_t>(kRowSlots), total += sz;
      if (sz == 0 || sz > static_cast<std::uint32_t>(kRowSlots)) continue;
      // window_min64 reads whole blocks of four records: [b, b + 4 ceil(sz / 4)).
      const char* lo = reinterpret_cast<const char*>(pts_.data() + b);
      const char* hi = reinterpret_cast<const char*>(pts_.data() + b + ((sz + 3) & ~3u)) - 1;
      for (const char* a = lo; a < hi; a += 64) prefetch(a);
      prefetch(hi);
    }
    S.fast = !big && total >= 1;
#else
    (void)S;
#endif
  }

  /// Stage three of batch_winners for a fast query: winner()'s certificates on window_min64's winner.
  Nearest finish(const WinSlot& S, const Vec3& d) const {
#if ASPERITY_GRID_FAST
    const Win w = window_min64(pts_.data(), S.runs, d.x(), d.y(), d.z());
    if (w.key < guard_[S.cell]) return Nearest{w.id, w.key, w.id, kInf};
    const Loc& L = S.L;
    const double* E = edge_.data();
    const double db = L.db, dc = L.dc, d3 = L.d3;
    const double xs = std::min(plane_x(db - E[L.i - 1] * d3, L.i - 1), plane_x(E[L.i + 2] * d3 - db, L.i + 2));
    const double xt = std::min(plane_x(dc - E[L.j - 1] * d3, L.j - 1), plane_x(E[L.j + 2] * d3 - dc, L.j + 2));
    if (beyond(std::min(std::min(xs, xt), d3 * d3), w.key)) return Nearest{w.id, w.key, w.id, kInf};
    return winner_only(search(S.L, d));
#else
    return winner(S.L, d);
#endif
  }

  // ---- cell edges -----------------------------------------------------------------------------

  void make_edges(double S) {
    S_ = S;
    const int G = G_;
    const auto g = static_cast<std::size_t>(G);
    const double A = std::atan(S);
    edge_.resize(g + 1);
    invn_.resize(g + 1);
    edge_[0] = -S;
    edge_[g] = S;
    for (int k = 1; k < G; ++k) edge_[static_cast<std::size_t>(k)] = 2 * k == G ? 0.0 : std::tan(-A + 2.0 * A * k / G);
    for (std::size_t k = 1; k <= g; ++k)
      if (!(edge_[k] > edge_[k - 1])) throw std::logic_error("grid backend: cell edges are not increasing");
    for (std::size_t k = 0; k <= g; ++k) invn_[k] = 1.0 / std::sqrt(1.0 + edge_[k] * edge_[k]);
    // Guess table: uniform bins in s no wider than the narrowest cell, each mapped to the cell of
    // its left end; cell_of() corrects the guess by exact comparisons.
    double narrow = 2.0 * S;
    for (std::size_t k = 0; k < g; ++k) narrow = std::min(narrow, edge_[k + 1] - edge_[k]);
    const int K = std::max(1, static_cast<int>(std::ceil(2.0 * S / narrow)) + 1);
    inv_w_ = K / (2.0 * S);
    guess_.resize(static_cast<std::size_t>(K));
    int cell = 0;
    for (int b = 0; b < K; ++b) {
      const double s = -S + b / inv_w_;
      while (cell + 1 < G && s >= edge_[static_cast<std::size_t>(cell) + 1]) ++cell;
      guess_[static_cast<std::size_t>(b)] = cell;
    }
  }

  /// The cell k with E_k <= s < E_(k+1), clamped to [0, G-1]; s must not be NaN.
  int cell_of(double s) const noexcept {
    const double u = std::clamp((s + S_) * inv_w_, 0.0, static_cast<double>(guess_.size() - 1));
    int k = guess_[static_cast<std::size_t>(u)];
    const double* E = edge_.data();
    k += static_cast<int>(k + 1 < G_ && s >= E[k + 1]);  // the usual single step, branch-free
    while (k + 1 < G_ && s >= E[k + 1]) ++k;
    while (k > 0 && s < E[k]) --k;
    return k;
  }

  // ---- build ----------------------------------------------------------------------------------

  /// The global cell of p on the face of axis a (and the sign of p_a), or kNone if not stored there.
  std::uint32_t cell_id(const Vec3& p, int a) const noexcept {
    const double pa = p[a];
    const double p3 = std::abs(pa);
    if (!(p3 > 0)) return kNone;
    // Most points are far outside two of their three candidate faces: skip those without the
    // division. Conservative: |p_b| > S (1 + 1e-9) p3 makes the computed s = p_b (1 / p3) (two
    // roundings of 2^-53) at least S in magnitude, outside [-S, S) as the test below would find.
    const double out = S_ * (1.0 + 1e-9) * p3;
    if (std::abs(p[(a + 1) % 3]) > out || std::abs(p[(a + 2) % 3]) > out) return kNone;
    const double r = 1.0 / p3;
    const double s = p[(a + 1) % 3] * r, t = p[(a + 2) % 3] * r;
    const double lo = edge_.front(), hi = edge_.back();
    if (!(s >= lo && s < hi && t >= lo && t < hi)) return kNone;
    const auto face = static_cast<std::uint32_t>(2 * a + (pa < 0 ? 1 : 0));
    const auto G = static_cast<std::uint32_t>(G_);
    return (face * G + static_cast<std::uint32_t>(cell_of(t))) * G + static_cast<std::uint32_t>(cell_of(s));
  }

  void build() {
    const std::size_t n = c_.size();
    const std::size_t ncell = 6 * static_cast<std::size_t>(G_) * static_cast<std::size_t>(G_);
    // Pass 1 (parallel, a pure function of each point): its cell on its three candidate faces.
    std::vector<std::uint32_t> cell(3 * n);
    const auto sn = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < sn; ++i) {
      const Vec3& p = c_[static_cast<std::size_t>(i)];
      for (int a = 0; a < 3; ++a) cell[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(a)] = cell_id(p, a);
    }
    // Pass 2: counting sort by cell, stable, so each cell lists its points in index order. About
    // half the candidate faces hold the point: branch-free, kNone + 1 wraps to 0 (cleared after).
    cs_.assign(ncell + 1, 0);
    std::uint32_t* cs = cs_.data();
    for (std::uint32_t v : cell) ++cs[static_cast<std::uint32_t>(v + 1)];
    cs_[0] = 0;
    std::uint64_t total = 0;
    for (std::size_t k = 1; k <= ncell; ++k) {
      total += cs_[k];
      if (total >= kNone - kPad) throw std::length_error("grid backend: too many stored points");
      cs_[k] = static_cast<std::uint32_t>(total);
    }
    // kPad readable slots past the end: the fast path reads whole runs of kRowSlots.
    pts_.assign(total + kPad, Pt{0.0, 0.0, 0.0, kNone, 0});
    // Branch-free too: a face that does not hold the point writes to the first pad slot (fill's
    // extra entry, never advanced), which is reset afterwards.
    std::vector<std::uint32_t> fill(cs_.begin(), cs_.end());
    Pt* pts = pts_.data();
    const auto dummy = static_cast<std::uint32_t>(ncell);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& p = c_[i];
      for (std::size_t a = 0; a < 3; ++a) {
        const std::uint32_t v = cell[3 * i + a], slot = v == kNone ? dummy : v;
        const std::uint32_t k = fill[slot];
        fill[slot] = k + (v == kNone ? 0u : 1u);
        pts[k] = Pt{p.x(), p.y(), p.z(), static_cast<std::uint32_t>(i), 0};
      }
    }
    pts_[total] = Pt{0.0, 0.0, 0.0, kNone, 0};
    // The float rows of the winner path (pads: 0, masked by the run sizes).
    fx_.assign(total + kPad, 0.0f), fy_.assign(total + kPad, 0.0f), fz_.assign(total + kPad, 0.0f);
    for (std::size_t k = 0; k < total; ++k) {
      fx_[k] = static_cast<float>(pts[k].x), fy_[k] = static_cast<float>(pts[k].y), fz_[k] = static_cast<float>(pts[k].z);
    }
    make_guards();
  }

  /// guard_[j G + i]: a key below which the 3x3 window's winner is the winner, for every direction
  /// located in cell (i, j) of any face (the faces are congruent); 0 for cells at the face border.
  /// A point outside the window lies beyond one of its four edge planes (edges moved inward by
  /// kSlack, as in search) or the plane p3 = 0; for d in the cell, y = n.d >= (E_i - E_(i-1) - 2
  /// kSlack) / (sqrt(1 + E_(i-1)^2) sqrt(1 + s_max^2 + t_max^2)) for the edge s = E_(i-1) (s >= E_i,
  /// |s| <= s_max, |t| <= t_max, both widened by kSlack), likewise the others, and y >= 1 / sqrt(1 +
  /// s_max^2 + t_max^2) for p3 = 0. A point beyond a plane at y has key >= 2 y^2 / (1 + sqrt(1 -
  /// y^2)); the guard is the key for the smallest y shrunk by beyond()'s margins and 1e-6 more.
  void make_guards() {
    const int G = G_;
    const double* E = edge_.data();
    guard_.assign(static_cast<std::size_t>(G) * static_cast<std::size_t>(G), 0.0);
    auto mag = [E](int k) { return std::max(std::abs(E[k]), std::abs(E[k + 1])) + kSlack; };
    for (int j = 1; j + 1 < G; ++j)
      for (int i = 1; i + 1 < G; ++i) {
        const double h = std::sqrt(1.0 + mag(i) * mag(i) + mag(j) * mag(j));
        auto side = [&](int a, int b) {  // edge b of the window, cell edge a on d's side
          return std::max(std::abs(E[a] - E[b]) - 2.0 * kSlack, 0.0) * invn_[static_cast<std::size_t>(b)] / h;
        };
        const double y = std::min({side(i, i - 1), side(i + 1, i + 2), side(j, j - 1), side(j + 1, j + 2), 1.0 / h});
        const double X = std::min(y * y * (1.0 - kRel), 1.0);
        const double K = 2.0 * X / (1.0 + std::sqrt(1.0 - X));  // K - K^2/4 = X
        guard_[static_cast<std::size_t>(j * G + i)] = std::min(K, 1.0) / (1.0 + kRel) * (1.0 - 1e-6);
      }
  }

  // ---- query ----------------------------------------------------------------------------------

  Loc locate(const Vec3& d) const noexcept {
    Loc L;
    if (brute_ || !is_unit(d.x(), d.y(), d.z())) return L;
    const double ax = std::abs(d.x()), ay = std::abs(d.y()), az = std::abs(d.z());
    const int a = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const double da = d[a];
    L.d3 = std::abs(da);
    L.db = d[(a + 1) % 3];
    L.dc = d[(a + 2) % 3];
    const double r = 1.0 / L.d3;
    L.i = cell_of(L.db * r);
    L.j = cell_of(L.dc * r);
    L.base = static_cast<std::uint32_t>(2 * a + (da < 0 ? 1 : 0)) * static_cast<std::uint32_t>(G_) *
             static_cast<std::uint32_t>(G_);
    L.brute = false;
    return L;
  }

  /// Prefetches the cell starts of the three runs around L (rows j-1..j+1, columns i-1..i+1).
  void prefetch_starts(const Loc& L) const noexcept {
    const std::uint32_t* cs = cs_.data() + L.base;
    const int i0 = std::max(L.i - 1, 0), i1 = std::min(L.i + 2, G_);
    for (int r = std::max(L.j - 1, 0); r <= std::min(L.j + 1, G_ - 1); ++r) {
      prefetch(cs + r * G_ + i0);
      prefetch(cs + r * G_ + i1);
    }
  }

  /// Prefetches the records the fast path reads of the three runs around L: every cache line of
  /// its blocks of four, [b, b + 4 ceil(n / 4)) for a run of n <= kRowSlots points (longer runs
  /// take the general path: their first kRowSlots).
  void prefetch_points(const Loc& L) const noexcept {
    const std::uint32_t* cs = cs_.data() + L.base;
    const int i0 = std::max(L.i - 1, 0), i1 = std::min(L.i + 2, G_);
    for (int r = std::max(L.j - 1, 0); r <= std::min(L.j + 1, G_ - 1); ++r) {
      const std::uint32_t b = cs[r * G_ + i0], n = std::min<std::uint32_t>(cs[r * G_ + i1] - b, kRowSlots);
      const char* lo = reinterpret_cast<const char*>(pts_.data() + b);
      const char* hi = reinterpret_cast<const char*>(pts_.data() + b + ((n + 3) & ~3u));
      for (const char* a = lo; a < hi; a += 64) prefetch(a);
      if (hi > lo) prefetch(hi - 1);
    }
  }

  /// x = y^2 for the plane through the window edge E_k, d at (unnormalised) height z on its inner
  /// side; conservative: the edge is moved inward by kSlack and the height reduced by 2 kSlack.
  double plane_x(double z, int k) const noexcept {
    const double y = std::max((z - 2.0 * kSlack) * invn_[static_cast<std::size_t>(k)], 0.0);
    return y * y;
  }

  /// True when every point beyond planes whose smallest x is `x` has a key strictly above k2.
  static bool beyond(double x, double k2) noexcept {
    const double K = k2 * (1.0 + kRel);
    return K < 1.0 && x * (1.0 - kRel) > K - 0.25 * K * K;
  }

  Nearest search(const Loc& L, const Vec3& d) const {
#if ASPERITY_GRID_FAST
    const int G = G_;
    if (L.i >= 1 && L.i + 1 < G && L.j >= 1 && L.j + 1 < G) {
      const std::uint32_t* cs = cs_.data() + L.base + (L.j - 1) * G + (L.i - 1);
      Runs runs;
      for (int r = 0; r < 3; ++r) {
        runs.begin[r] = cs[r * G];
        runs.size[r] = cs[r * G + 3] - runs.begin[r];
      }
      if (std::max(std::max(runs.size[0], runs.size[1]), runs.size[2]) <= kRowSlots &&
          runs.size[0] + runs.size[1] + runs.size[2] >= 2) {
        const TopPair t = top_pair(pts_.data(), runs, d.x(), d.y(), d.z());
        if (t.ok) {
          const double* E = edge_.data();
          const double db = L.db, dc = L.dc, d3 = L.d3;
          const double xs = std::min(plane_x(db - E[L.i - 1] * d3, L.i - 1), plane_x(E[L.i + 2] * d3 - db, L.i + 2));
          const double xt = std::min(plane_x(dc - E[L.j - 1] * d3, L.j - 1), plane_x(E[L.j + 2] * d3 - dc, L.j + 2));
          if (beyond(std::min(std::min(xs, xt), d3 * d3), t.k2)) return Nearest{t.i1, t.k1, t.i2, t.k2};
          TopTwo top;  // the 3x3 window's top two; grow from there
          top.offer(t.i1, t.k1);
          top.offer(t.i2, t.k2);
          return grow(L, d, top, true);
        }
      }
    }
#endif
    return grow(L, d, TopTwo{}, false);
  }

  /// The winner alone (lowest_winners): the 3x3 window's winner by the float kernel, certified by
  /// the cell's guard (every point outside the window has a key above it, for any direction in the
  /// cell), else by this direction's own plane bound; otherwise the full search decides.
  /// Inline: the float kernel inlined (the ISA-cloned resident loop) instead of called through
  /// its own clones' dispatch.
  template <bool Inline = false>
  [[gnu::always_inline]] inline Nearest winner(const Loc& L, const Vec3& d) const {
    if (L.brute) return winner_only(brute_lowest(c_, d));
#if ASPERITY_GRID_FAST
    const int G = G_;
    const double g = guard_[static_cast<std::size_t>(L.j * G + L.i)];  // 0 at the face border
    if (g > 0) {
      const std::uint32_t* cs = cs_.data() + L.base + (L.j - 1) * G + (L.i - 1);
      Runs runs;
      for (int r = 0; r < 3; ++r) {
        runs.begin[r] = cs[r * G];
        runs.size[r] = cs[r * G + 3] - runs.begin[r];
      }
      if (std::max(std::max(runs.size[0], runs.size[1]), runs.size[2]) <= kRowSlots &&
          runs.size[0] + runs.size[1] + runs.size[2] >= 1) {
        Win w;
        if constexpr (Inline)
          w = recheck(pts_.data(), runs, float_candidates(fx_.data(), fy_.data(), fz_.data(), runs, d.x(), d.y(), d.z()),
                      d.x(), d.y(), d.z());
        else
          w = window_winner(fx_.data(), fy_.data(), fz_.data(), pts_.data(), runs, d.x(), d.y(), d.z());
        if (w.key < g) return Nearest{w.id, w.key, w.id, kInf};
        const double* E = edge_.data();
        const double db = L.db, dc = L.dc, d3 = L.d3;
        const double xs = std::min(plane_x(db - E[L.i - 1] * d3, L.i - 1), plane_x(E[L.i + 2] * d3 - db, L.i + 2));
        const double xt = std::min(plane_x(dc - E[L.j - 1] * d3, L.j - 1), plane_x(E[L.j + 2] * d3 - dc, L.j + 2));
        if (beyond(std::min(std::min(xs, xt), d3 * d3), w.key)) return Nearest{w.id, w.key, w.id, kInf};
      }
    }
#endif
    return winner_only(search(L, d));
  }

  void scan(std::uint32_t b, std::uint32_t e, const Vec3& d, TopTwo& top) const noexcept {
    for (std::uint32_t k = b; k < e; ++k) {
      const Pt& p = pts_[k];
      const double x = p.x - d.x(), y = p.y - d.y(), z = p.z - d.z();
      top.offer(p.id, x * x + y * y + z * z);  // contact_key's expression
    }
  }

  /// The general search: from the (clamped) 3x3 window, already scanned into `top` when
  /// `scanned`, move the limiting window edge out by one row or column until the bound holds.
  Nearest grow(const Loc& L, const Vec3& d, TopTwo top, bool scanned) const {
    const int G = G_;
    const std::uint32_t* cs = cs_.data() + L.base;
    const double* E = edge_.data();
    const double db = L.db, dc = L.dc, d3 = L.d3;
    int i0 = std::max(L.i - 1, 0), i1 = std::min(L.i + 1, G - 1);
    int j0 = std::max(L.j - 1, 0), j1 = std::min(L.j + 1, G - 1);
    if (!scanned)
      for (int r = j0; r <= j1; ++r) scan(cs[r * G + i0], cs[r * G + i1 + 1], d, top);
    // x[e]: squared sine of the angular distance from d to the plane of window edge e
    // (0: s = E_i0, 1: s = E_(i1+1), 2: t = E_j0, 3: t = E_(j1+1)); x5: the plane p3 = 0.
    std::array<double, 4> x{plane_x(db - E[i0] * d3, i0), plane_x(E[i1 + 1] * d3 - db, i1 + 1),
                            plane_x(dc - E[j0] * d3, j0), plane_x(E[j1 + 1] * d3 - dc, j1 + 1)};
    const double x5 = d3 * d3;
    for (;;) {
      int e = 0;
      double m = x[0];
      for (int k = 1; k < 4; ++k)
        if (x[static_cast<std::size_t>(k)] < m) m = x[static_cast<std::size_t>(k)], e = k;
      if (beyond(std::min(m, x5), top.second_key())) break;
      // The limiting plane cannot move: nothing scanned later on this face could meet the bound.
      if (x5 <= m) return brute_lowest(c_, d);
      switch (e) {
        case 0:
          if (i0 == 0) return brute_lowest(c_, d);
          --i0;
          for (int r = j0; r <= j1; ++r) scan(cs[r * G + i0], cs[r * G + i0 + 1], d, top);
          x[0] = plane_x(db - E[i0] * d3, i0);
          break;
        case 1:
          if (i1 == G - 1) return brute_lowest(c_, d);
          ++i1;
          for (int r = j0; r <= j1; ++r) scan(cs[r * G + i1], cs[r * G + i1 + 1], d, top);
          x[1] = plane_x(E[i1 + 1] * d3 - db, i1 + 1);
          break;
        case 2:
          if (j0 == 0) return brute_lowest(c_, d);
          --j0;
          scan(cs[j0 * G + i0], cs[j0 * G + i1 + 1], d, top);
          x[2] = plane_x(dc - E[j0] * d3, j0);
          break;
        default:
          if (j1 == G - 1) return brute_lowest(c_, d);
          ++j1;
          scan(cs[j1 * G + i0], cs[j1 * G + i1 + 1], d, top);
          x[3] = plane_x(E[j1 + 1] * d3 - dc, j1 + 1);
          break;
      }
    }
    return top.result();
  }

  std::span<const Vec3> c_;
  bool brute_ = true;  // centres not all unit vectors: every query by brute force
  int G_ = 1;          // cells per face edge
  double S_ = 1;       // half-width of the extended face
  double inv_w_ = 1;   // guess-table bins per unit of s
  std::vector<double> edge_;         // E_0..E_G
  std::vector<double> invn_;         // 1 / sqrt(1 + E_k^2)
  std::vector<std::int32_t> guess_;  // uniform bin -> cell guess
  Array<std::uint32_t> cs_;          // cell starts, 6 G^2 + 1
  Array<Pt> pts_;                    // stored points and their original indices (+ kPad)
  Array<float> fx_, fy_, fz_;        // pts_'s coordinates rounded to float (+ kPad): the winner path
  std::vector<double> guard_;        // per face cell (j G + i): the winner path's certificate
};

/// lowest_winners of an index that fits in L2, query by query, the whole loop compiled per ISA
/// (one dispatch per batch instead of one per query; the same IEEE operations: the same answers).
ASPERITY_GRID_CLONES
void resident_winners(const Grid& g, std::span<const Vec3> d, std::span<Nearest> out) {
  for (std::size_t q = 0; q < d.size(); ++q) out[q] = g.winner<true>(g.locate(d[q]), d[q]);
}

}  // namespace

/// Grid with an explicit side (cells per face edge) and margin; <= 0 selects the default.
/// Not in detail.hpp: for tests and benchmarks that need coarse or fine grids.
std::unique_ptr<ContactQuery> make_grid_with(std::span<const Vec3> centres, int side, double margin) {
  return std::make_unique<Grid>(centres, side, margin);
}

std::unique_ptr<ContactQuery> make_grid(std::span<const Vec3> centres) { return make_grid_with(centres, 0, 0); }

}  // namespace asperity::detail
