// The layer row kernels (layer_rows.h), one at a time: each C reference against its definition
// written out in wide arithmetic (int64 / double, no prefix sums, no wrapping), and every faster
// variant the CPU has against the C reference, bit for bit, on random inputs and on inputs at
// the edges of the overflow bounds the header states.
#include "algo/render/layer_rows.h"

#include "algo/core/cpu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

namespace lb {
namespace {

using layer_rows::Kernels;

constexpr int32_t kMaxV = 2040;                         // |v|: 255 x the largest highlight gain 8
constexpr int32_t kCells = 17 * 17;                     // the largest kernel at its level
constexpr int32_t kMaxC = 2147483647 / (kCells * 256);  // |c| that keeps a kernel sum < 2^31

// Every variant of the table kernels this CPU runs, by name (the reference first).
std::vector<std::pair<const char*, const Kernels*>> Variants() {
  std::vector<std::pair<const char*, const Kernels*>> v = {{"C", &layer_rows::kReference}};
  if (const Kernels* k = layer_rows::Avx2Kernels()) v.emplace_back("AVX2", k);
  // armhf builds the NEON twins whatever its baseline: run them only where the CPU has NEON (as
  // the tests' main read it, tests/support/test_main.cc).
  const Kernels* neon = layer_rows::NeonKernels();
  if (neon != nullptr && CurrentCpu().neon) v.emplace_back("NEON", neon);
  return v;
}

void SkipWithoutVariants() {
  if (Variants().size() < 2) GTEST_SKIP() << "no faster variant of the layer row kernels here";
}

// A random kernel row whose cells lie within [-half, half].
KernelRow RandomRow(std::mt19937& rng, int32_t half, bool extreme) {
  std::uniform_int_distribution<int32_t> pos(-half, half), weight(0, 256);
  KernelRow r;
  int32_t a = pos(rng), b = pos(rng);
  if (a > b) std::swap(a, b);
  r.left = static_cast<int16_t>(a + 1);                // ends at a and b
  r.right = static_cast<int16_t>(a == b ? a : b - 1);  // as BuildKernel: right >= left - 1
  r.w = static_cast<int16_t>(extreme ? 256 : weight(rng));
  r.wl = static_cast<int16_t>(extreme ? 256 : weight(rng));
  r.wr = static_cast<int16_t>(extreme || a == b ? (a == b ? 0 : 256) : weight(rng));
  return r;
}

// Values c, their wrapping prefix p (p[i] = sum of c below column i), with `pad` columns of
// margin either side of [0, n).
struct PrefixRow {
  static constexpr int32_t kPad = 20;
  std::vector<int32_t> c;
  std::vector<uint32_t> p;
  int32_t C(int32_t x) const { return c[x + kPad]; }
  const uint32_t* P() const { return p.data() + kPad; }
};

PrefixRow MakePrefix(std::mt19937& rng, int32_t n, int32_t max_c, bool extreme) {
  PrefixRow r;
  std::uniform_int_distribution<int32_t> value(-max_c, max_c);
  r.c.resize(n + 2 * PrefixRow::kPad);
  for (int32_t& v : r.c) v = extreme ? ((rng() & 1) ? max_c : -max_c) : value(rng);
  r.p.assign(r.c.size() + 1, 0);
  // Start from a large offset: only differences matter, and they must survive the wrap.
  r.p[0] = rng();
  for (size_t i = 0; i < r.c.size(); ++i) r.p[i + 1] = r.p[i] + static_cast<uint32_t>(r.c[i]);
  return r;
}

TEST(LayerRows, GatherRowIsTheWeightedSumOfTheCells) {
  std::mt19937 rng(1);
  for (int32_t trial = 0; trial < 400; ++trial) {
    const bool extreme = trial % 4 == 0;
    const int32_t n = 1 + trial % 70, half = trial % 9;
    const PrefixRow row = MakePrefix(rng, n, kMaxC, extreme);
    const KernelRow k = RandomRow(rng, half, extreme);
    std::vector<uint32_t> acc(n);
    std::vector<int64_t> expected(n);
    for (int32_t x = 0; x < n; ++x) {
      // At the bound: a row's sum on top of an accumulator near +-2^31 (the other rows).
      const int64_t row_max = int64_t{k.right - k.left + 3} * 256 * kMaxC;
      const int32_t start =
          extreme ? static_cast<int32_t>(((rng() & 1) ? 1 : -1) * (INT32_MAX - row_max))
                  : static_cast<int32_t>(rng() % 1000000) - 500000;
      acc[x] = static_cast<uint32_t>(start);
      int64_t sum = start;
      for (int32_t d = k.left; d <= k.right; ++d) sum += int64_t{k.w} * row.C(x + d);
      sum += int64_t{k.wl} * row.C(x + k.left - 1);
      sum += int64_t{k.wr} * row.C(x + k.right + 1);
      expected[x] = sum;
    }
    layer_rows::GatherRowC(row.P(), k, acc.data(), 0, n - 1);
    for (int32_t x = 0; x < n; ++x) {
      ASSERT_EQ(static_cast<int32_t>(acc[x]), expected[x]) << "trial " << trial << " x " << x;
    }
  }
}

TEST(LayerRows, GatherRowVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(2);
  for (int32_t trial = 0; trial < 400; ++trial) {
    const bool extreme = trial % 3 == 0;
    const int32_t n = 1 + trial % 90, half = trial % 9;
    // Beyond the bound too: wrapping arithmetic must agree whatever the values.
    const PrefixRow row = MakePrefix(rng, n, trial % 5 == 0 ? 1 << 30 : kMaxC, extreme);
    const KernelRow k = RandomRow(rng, half, extreme);
    const int32_t x0 = static_cast<int32_t>(rng() % n), x1 = n - 1;
    std::vector<uint32_t> init(n);
    for (uint32_t& a : init) a = rng();
    std::vector<uint32_t> want = init;
    layer_rows::kReference.gather(row.P(), k, want.data(), x0, x1);
    for (const auto& [name, kernels] : Variants()) {
      std::vector<uint32_t> got = init;
      kernels->gather(row.P(), k, got.data(), x0, x1);
      ASSERT_EQ(got, want) << name << " trial " << trial;
    }
  }
}

// Q16 layer rows: colour premultiplied (|colour| <= alpha x kMaxV), alpha 0..65536.
struct LayerRow {
  std::vector<int32_t> out, colour, alpha;
};

LayerRow MakeLayerRow(std::mt19937& rng, int32_t n, bool extreme) {
  LayerRow r;
  std::uniform_int_distribution<int32_t> alpha(0, 65536), unit(-65536, 65536);
  for (int32_t x = 0; x < n; ++x) {
    const int32_t a = extreme ? ((rng() & 1) ? 65536 : 0) : alpha(rng);
    const int64_t sign = (rng() & 1) ? 1 : -1;
    r.alpha.push_back(a);
    r.colour.push_back(
        static_cast<int32_t>(extreme ? sign * a * kMaxV : int64_t{a} * kMaxV * unit(rng) / 65536));
    r.out.push_back(extreme ? static_cast<int32_t>(sign * -kMaxV * 65536)
                            : static_cast<int32_t>(int64_t{kMaxV} * unit(rng)));
  }
  return r;
}

TEST(LayerRows, CompositeRowLaysTheLayerOverWhatIsBehind) {
  std::mt19937 rng(3);
  for (int32_t trial = 0; trial < 200; ++trial) {
    const int32_t n = 1 + trial % 40;
    LayerRow r = MakeLayerRow(rng, n, trial % 2 == 0);
    std::vector<int32_t> expected(n);
    for (int32_t x = 0; x < n; ++x) {
      const int64_t keep = 65536 - r.alpha[x];
      expected[x] = static_cast<int32_t>(
          std::floor((static_cast<double>(r.out[x]) * static_cast<double>(keep) + 32768.0) /
                     65536.0) +
          r.colour[x]);
    }
    layer_rows::CompositeRowC(r.out.data(), r.colour.data(), r.alpha.data(), 0, n - 1);
    ASSERT_EQ(r.out, expected) << "trial " << trial;
  }
}

TEST(LayerRows, CompositeRowVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(4);
  for (int32_t trial = 0; trial < 300; ++trial) {
    const int32_t n = 1 + trial % 90;
    const LayerRow r = MakeLayerRow(rng, n, trial % 3 == 0);
    const int32_t x0 = static_cast<int32_t>(rng() % n);
    std::vector<int32_t> want = r.out;
    layer_rows::kReference.composite(want.data(), r.colour.data(), r.alpha.data(), x0, n - 1);
    for (const auto& [name, kernels] : Variants()) {
      std::vector<int32_t> got = r.out;
      kernels->composite(got.data(), r.colour.data(), r.alpha.data(), x0, n - 1);
      ASSERT_EQ(got, want) << name << " trial " << trial;
    }
  }
}

// The interpolated value of a reduced row at output column x (as LerpCompositeC defines it).
int32_t Lerp(const int32_t* col, int32_t level, const uint8_t* frac, int32_t x) {
  const int32_t f = 1 << level;
  const int32_t q = (x - f / 2) >> level;
  const int64_t d = int64_t{col[q + 1]} - col[q];
  return col[q] + static_cast<int32_t>((d * frac[x] + 128) >> 8);
}

template <int C>
void CheckLerpComposite(std::mt19937& rng, bool extreme) {
  for (int32_t level = 1; level <= 4; ++level) {
    const int32_t f = 1 << level;
    const int32_t n = 5 + static_cast<int32_t>(rng() % 80);
    const int32_t low = (n >> level) + 3;
    const ptrdiff_t stride = low + 2;  // col[-1] .. col[low]
    std::vector<int32_t> col((C + 1) * stride);
    for (int32_t q = 0; q < stride; ++q) {
      const LayerRow r = MakeLayerRow(rng, 1, extreme);
      col[C * stride + q] = r.alpha[0];
      for (int32_t c = 0; c < C; ++c) col[c * stride + q] = MakeLayerRow(rng, 1, extreme).colour[0];
      for (int32_t c = 0; c < C; ++c) {  // premultiplied by this alpha
        col[c * stride + q] =
            static_cast<int32_t>(int64_t{col[c * stride + q]} * r.alpha[0] / 65536);
      }
    }
    std::vector<uint8_t> frac(n);
    for (int32_t x = 0; x < n; ++x)
      frac[x] = static_cast<uint8_t>((((2 * x + 1 - f) * 128) >> level) & 255);
    const LayerRow behind = MakeLayerRow(rng, (C + 1) * n, extreme);
    std::vector<int32_t> out = behind.out, expected = behind.out;
    const int32_t x0 = static_cast<int32_t>(rng() % n);
    for (int32_t x = x0; x < n; ++x) {
      const int32_t alpha = Lerp(col.data() + 1 + C * stride, level, frac.data(), x);
      const int64_t keep = 65536 - alpha;
      for (int32_t c = 0; c <= C; ++c) {
        const int32_t v = c == C ? alpha : Lerp(col.data() + 1 + c * stride, level, frac.data(), x);
        int32_t& o = expected[c * n + x];
        o = static_cast<int32_t>(((o * keep + 32768) >> 16) + v);
      }
    }
    layer_rows::LerpCompositeC<C>(col.data() + 1, stride, frac.data(), level, x0, n - 1, out.data(),
                                  n);
    ASSERT_EQ(out, expected) << "C " << C << " level " << level;
  }
}

TEST(LayerRows, LerpCompositeInterpolatesThenComposites) {
  std::mt19937 rng(5);
  for (int32_t trial = 0; trial < 50; ++trial) {
    CheckLerpComposite<1>(rng, trial % 2 == 0);
    CheckLerpComposite<2>(rng, trial % 2 == 0);
  }
}

TEST(LayerRows, SumGroupsAddsEachGroupShifted) {
  std::mt19937 rng(6);
  std::uniform_int_distribution<int32_t> value(-kMaxV, kMaxV);
  for (int32_t trial = 0; trial < 400; ++trial) {
    const int32_t level = 1 + trial % 4, up = trial % 9, n = 1 + trial % 100;
    const bool extreme = trial % 3 == 0;
    std::vector<int16_t> v(n);
    const int16_t sign = (rng() & 1) ? 1 : -1;
    for (int16_t& s : v) s = static_cast<int16_t>(extreme ? sign * kMaxV : value(rng));
    // Groups start at a multiple of 2^level (tile edges, in the plane).
    const int32_t x0 = static_cast<int32_t>(rng() % n) & ~((1 << level) - 1);
    const int32_t x1 = x0 + static_cast<int32_t>(rng() % (n - x0));
    // A whole box of 2^level rows of the same values: the largest sum the bound allows.
    std::vector<int32_t> box((n >> level) + 1, 0), expected = box;
    for (int32_t row = 0; row < (1 << level); ++row) {
      layer_rows::SumGroupsC(v.data(), x0, x1, level, up, box.data());
      for (int32_t x = x0; x <= x1; ++x) expected[x >> level] += v[x] * (1 << up);
    }
    ASSERT_EQ(box, expected) << "trial " << trial;
  }
}

TEST(LayerRows, NormaliseRowsScaleByTheReciprocal) {
  std::mt19937 rng(7);
  for (int32_t trial = 0; trial < 300; ++trial) {
    const bool extreme = trial % 3 == 0;
    // A kernel's total weight (Q8 cells): 256 (the identity) .. 17 x 17 x 256.
    const uint32_t total = extreme ? (trial % 2 ? 256u : 256u * kCells)
                                   : 256u + static_cast<uint32_t>(rng() % (256u * kCells - 255));
    const uint64_t rec = (uint64_t{1} << 40) / total;
    const int32_t shift = static_cast<int32_t>(rng() % 9), n = 1 + trial % 50;
    // |c| within both the value range and the kernel-sum bound (total x |c| < 2^31).
    const int64_t max_c = std::min<int64_t>((int64_t{kMaxV} * 256) >> shift, INT32_MAX / total);
    std::vector<uint32_t> acc_a(n), acc_c(n);
    for (int32_t x = 0; x < n; ++x) {
      acc_a[x] = extreme ? total * 256 : static_cast<uint32_t>(rng() % (uint64_t{total} * 256 + 1));
      const int64_t c = extreme ? (trial % 4 < 2 ? max_c : -max_c)
                                : static_cast<int64_t>(rng() % (2 * max_c + 1)) - max_c;
      acc_c[x] = static_cast<uint32_t>(static_cast<int32_t>(c * total));  // total x c fits
    }
    std::vector<int32_t> alpha(n), colour(n);
    layer_rows::NormaliseAlphaRowC(acc_a.data(), rec, 0, n - 1, alpha.data());
    layer_rows::NormaliseColourRowC(acc_c.data(), rec, shift, 0, n - 1, colour.data());
    for (int32_t x = 0; x < n; ++x) {
      // Exact in 64 bits on every target (armhf has no __int128): acc_a <= total x 2^8 and
      // rec <= 2^40 / total, so acc_a x rec <= 2^48; |acc_c| <= INT32_MAX and rec <= 2^32, so
      // |acc_c x rec| < 2^63.
      const uint64_t a = (uint64_t{acc_a[x]} * rec) >> 32;
      ASSERT_EQ(alpha[x], a > 65536 ? 65536 : static_cast<int32_t>(a)) << trial;
      ASSERT_LE(alpha[x], 65536);
      const int64_t c =
          (int64_t{static_cast<int32_t>(acc_c[x])} * static_cast<int64_t>(rec)) >> (32 - shift);
      ASSERT_EQ(colour[x], static_cast<int32_t>(c)) << trial;
      // Q16 of v: within the value range (plus rounding of the reciprocal).
      ASSERT_LE(std::abs(colour[x]), kMaxV * 65536 + 65536) << trial;
    }
  }
}

TEST(LayerRows, BlendRowsMixesTwoRowsAndReplicatesTheEdges) {
  std::mt19937 rng(8);
  for (int32_t trial = 0; trial < 200; ++trial) {
    const int32_t n = 1 + trial % 40;
    const LayerRow ra = MakeLayerRow(rng, n, trial % 2 == 0),
                   rb = MakeLayerRow(rng, n, trial % 3 == 0);
    const int64_t fy = static_cast<int64_t>(rng() % 256);
    std::vector<int32_t> col(n + 2);
    layer_rows::BlendRowsC(ra.colour.data(), rb.colour.data(), fy, 0, n - 1, col.data() + 1);
    for (int32_t q = 0; q < n; ++q) {
      const double mix = (static_cast<double>(ra.colour[q]) * static_cast<double>(256 - fy) +
                          static_cast<double>(rb.colour[q]) * static_cast<double>(fy) + 128) /
                         256.0;
      ASSERT_EQ(col[q + 1], static_cast<int32_t>(std::floor(mix))) << trial;
    }
    ASSERT_EQ(col[0], col[1]);
    ASSERT_EQ(col[n + 1], col[n]);
  }
}

TEST(LayerRows, ResolveRowDividesRoundsAndClamps) {
  std::mt19937 rng(9);
  for (int32_t trial = 0; trial < 200; ++trial) {
    const int32_t n = 1 + trial % 60;
    const bool extreme = trial % 2 == 0;
    LayerRow r = MakeLayerRow(rng, n, extreme);
    std::vector<int16_t> v(n);
    for (int32_t x = 0; x < n; ++x) {
      v[x] = static_cast<int16_t>(static_cast<int32_t>(rng() % (2 * kMaxV + 1)) - kMaxV);
      if (x % 7 == 3) r.alpha[x] = 0;  // the fallback: the pixel's own value
    }
    const int32_t bias = trial % 3 == 0 ? 0 : 128;
    std::vector<uint8_t> dst(n);
    layer_rows::ResolveRowC(r.colour.data(), r.alpha.data(), v.data(), n, bias, dst.data());
    for (int32_t x = 0; x < n; ++x) {
      int32_t value = v[x];
      if (r.alpha[x] > 0) {
        const double q = static_cast<double>(r.colour[x]) / r.alpha[x];
        value = static_cast<int32_t>(q >= 0 ? std::floor(q + 0.5) : -std::floor(-q + 0.5));
      }
      const int32_t b = value + bias;
      ASSERT_EQ(dst[x], b < 0 ? 0 : (b > 255 ? 255 : b)) << trial << " x " << x;
    }
  }
}

TEST(LayerRows, LayerWeightsOfAPixelSumTo256) {
  for (int32_t first = 0; first < 79; ++first) {
    for (int32_t frac = 0; frac < 256; frac += 5) {
      const uint16_t e = static_cast<uint16_t>(first << 8 | frac);
      int32_t sum = 0;
      for (int32_t k = 0; k < 80; ++k) sum += layer_rows::LayerWeightQ8(e, k);
      ASSERT_EQ(sum, 256) << first << " " << frac;
      ASSERT_EQ(layer_rows::LayerWeightQ8(e, first), 256 - frac);
    }
  }
}

// A layer's rows: C value rows, a radius row and a layer_of table mapping radius + offset to
// an entry whose first layer is 0..3.
template <int C>
struct LayerInput {
  static constexpr int32_t kOffset = 64;
  std::vector<std::vector<int16_t>> v = std::vector<std::vector<int16_t>>(C);
  std::vector<int16_t> s;
  std::vector<uint16_t> layer_of = std::vector<uint16_t>(2 * kOffset + 1);
  const int16_t* rows[C];
  LayerInput(std::mt19937& rng, int32_t n, bool extreme, bool pure_in = false, int32_t k = 0) {
    for (uint16_t& e : layer_of) {
      e = static_cast<uint16_t>(pure_in ? k << 8
                                        : (rng() % 4) << 8 | (extreme ? 255 : rng() % 256));
    }
    const int16_t sign = (rng() & 1) ? 1 : -1;
    for (int32_t c = 0; c < C; ++c) {
      for (int32_t x = 0; x < n; ++x) {
        v[c].push_back(static_cast<int16_t>(
            extreme ? sign * kMaxV : static_cast<int32_t>(rng() % (2 * kMaxV + 1)) - kMaxV));
      }
      rows[c] = v[c].data();
    }
    for (int32_t x = 0; x < n; ++x)
      s.push_back(static_cast<int16_t>(static_cast<int32_t>(rng() % (2 * kOffset + 1)) - kOffset));
  }
  int32_t A(int32_t x, int32_t k) const {
    return layer_rows::LayerWeightQ8(layer_of[s[x] + kOffset], k);
  }
};

template <int C>
void CheckPrefixRows(std::mt19937& rng, int32_t trial) {
  const int32_t n = 1 + trial % 70, k = trial % 4, shift = trial % 9;
  const bool extreme = trial % 3 == 0;
  const LayerInput<C> in(rng, n, extreme);
  const int32_t x0 = static_cast<int32_t>(rng() % n);
  for (int32_t kind = 0; kind < 3; ++kind) {
    std::vector<std::vector<uint32_t>> prefix(C + 1, std::vector<uint32_t>(n + 1));
    uint32_t* p[C + 1];
    for (int32_t c = 0; c <= C; ++c) {
      prefix[c][x0] = rng();  // any start: only differences are read
      p[c] = prefix[c].data();
    }
    if (kind == 0) layer_rows::FlatPrefixRowC<C>(x0, n - 1, p);
    if (kind == 1) layer_rows::PurePrefixRowC<C>(in.rows, shift, x0, n - 1, p);
    if (kind == 2) {
      layer_rows::WeightedPrefixRowC<C>(in.rows, in.s.data(), in.layer_of.data(),
                                        LayerInput<C>::kOffset, k, shift, x0, n - 1, p);
    }
    for (int32_t x = x0; x < n; ++x) {
      const int32_t a = kind == 0 ? 0 : kind == 1 ? 256 : in.A(x, k);
      for (int32_t c = 0; c <= C; ++c) {
        const int32_t want = c == C ? a : (in.v[c][x] * a) >> shift;
        ASSERT_EQ(static_cast<int32_t>(prefix[c][x + 1] - prefix[c][x]), want)
            << "kind " << kind << " trial " << trial << " x " << x << " c " << c;
      }
    }
  }
}

TEST(LayerRows, PrefixRowsAddEachPixelsWeightedValue) {
  std::mt19937 rng(21);
  for (int32_t trial = 0; trial < 200; ++trial) {
    CheckPrefixRows<1>(rng, trial);
    CheckPrefixRows<2>(rng, trial);
  }
}

// The weighted prefix rows' twins against the reference, from any start, over lengths that
// leave every remainder of a step and with the largest values.
template <int C>
void CheckPrefixRowVariants(std::mt19937& rng, int32_t trial) {
  const int32_t n = 1 + trial % 90, k = trial % 4, shift = trial % 9;
  const LayerInput<C> in(rng, n, trial % 3 == 0);
  const int32_t x0 = static_cast<int32_t>(rng() % n);
  std::vector<uint32_t> start(C + 1);
  for (uint32_t& v : start) v = rng();
  const auto run = [&](const Kernels* kernels) {
    std::vector<std::vector<uint32_t>> prefix(C + 1, std::vector<uint32_t>(n + 1, 0));
    uint32_t* p[C + 1];
    for (int32_t c = 0; c <= C; ++c) {
      prefix[c][x0] = start[c];
      p[c] = prefix[c].data();
    }
    kernels->weighted_prefix[C - 1](in.rows, in.s.data(), in.layer_of.data(),
                                    LayerInput<C>::kOffset, k, shift, x0, n - 1, p);
    return prefix;
  };
  const auto want = run(&layer_rows::kReference);
  for (const auto& [name, kernels] : Variants()) {
    ASSERT_EQ(run(kernels), want) << name << " C " << C << " trial " << trial;
  }
}

TEST(LayerRows, PrefixRowVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(36);
  for (int32_t trial = 0; trial < 300; ++trial) {
    CheckPrefixRowVariants<1>(rng, trial);
    CheckPrefixRowVariants<2>(rng, trial);
  }
}

// A box row's case: a level, a layer, a shift, columns [x0, x1] from a box edge, and the rows
// of a pixel mix and of a tile wholly in the layer.
template <int C>
struct BoxCase {
  const int32_t level, n, k, shift;
  const bool extreme;
  const int32_t x0, x1, boxes;
  const LayerInput<C> mixed, pure;
  BoxCase(std::mt19937& rng, int32_t trial, int32_t max_n)
      : level(1 + trial % 4),
        n(1 + trial % max_n),
        k(trial % 4),
        shift(trial % 9),
        extreme(trial % 3 == 0),
        x0(static_cast<int32_t>(rng() % n) & ~((1 << level) - 1)),
        x1(x0 + static_cast<int32_t>(rng() % (n - x0))),
        boxes((n >> level) + 1),
        mixed(rng, n, extreme),
        pure(rng, n, extreme, true, k) {}
};

template <int C>
void CheckBoxRows(std::mt19937& rng, int32_t trial) {
  const BoxCase<C> bc(rng, trial, 90);
  const auto& [level, n, k, shift, extreme, x0, x1, boxes, mixed, pure] = bc;
  // A whole box of rows (the largest sums), weighted; and a pure one both ways.
  std::vector<std::vector<int32_t>> got(C + 1, std::vector<int32_t>(boxes, 0));
  std::vector<std::vector<int32_t>> want = got, pure_w = got, pure_p = got;
  int32_t* g[C + 1];
  int32_t* pw[C + 1];
  int32_t* pp[C + 1];
  for (int32_t c = 0; c <= C; ++c)
    g[c] = got[c].data(), pw[c] = pure_w[c].data(), pp[c] = pure_p[c].data();
  for (int32_t row = 0; row < (1 << level); ++row) {
    layer_rows::WeightedBoxRowC<C>(mixed.rows, mixed.s.data(), mixed.layer_of.data(),
                                   LayerInput<C>::kOffset, k, shift, level, x0, x1, g);
    for (int32_t x = x0; x <= x1; ++x) {
      const int32_t a = mixed.A(x, k);
      for (int32_t c = 0; c < C; ++c) want[c][x >> level] += (mixed.v[c][x] * a) >> shift;
      want[C][x >> level] += a;
    }
    layer_rows::WeightedBoxRowC<C>(pure.rows, pure.s.data(), pure.layer_of.data(),
                                   LayerInput<C>::kOffset, k, shift, level, x0, x1, pw);
    layer_rows::PureBoxRowC<C>(pure.rows, shift, level, x0, x1, pp);
  }
  ASSERT_EQ(got, want) << "trial " << trial;
  ASSERT_EQ(pure_p, pure_w) << "trial " << trial;  // the shortcut gives the same sums
}

TEST(LayerRows, BoxRowsSumEachBoxAndThePureShortcutAgrees) {
  std::mt19937 rng(22);
  for (int32_t trial = 0; trial < 300; ++trial) {
    CheckBoxRows<1>(rng, trial);
    CheckBoxRows<2>(rng, trial);
  }
}

template <int C>
void CheckBoxRowVariants(std::mt19937& rng, int32_t trial) {
  const BoxCase<C> bc(rng, trial, 130);
  const auto& [level, n, k, shift, extreme, x0, x1, boxes, mixed, pure] = bc;
  std::vector<std::vector<int32_t>> start(C + 1, std::vector<int32_t>(boxes));
  for (auto& plane : start) {
    for (int32_t& b : plane) b = static_cast<int32_t>(rng() % 2000001) - 1000000;
  }
  const auto run = [&](const Kernels* kernels) {
    std::vector<std::vector<int32_t>> w = start, p = start;
    int32_t* pw[C + 1];
    int32_t* pp[C + 1];
    for (int32_t c = 0; c <= C; ++c) pw[c] = w[c].data(), pp[c] = p[c].data();
    // A whole box of rows: the largest sums.
    for (int32_t row = 0; row < (1 << level); ++row) {
      kernels->weighted_box[C - 1](mixed.rows, mixed.s.data(), mixed.layer_of.data(),
                                   LayerInput<C>::kOffset, k, shift, level, x0, x1, pw);
      kernels->pure_box[C - 1](pure.rows, shift, level, x0, x1, pp);
    }
    return std::make_pair(w, p);
  };
  const auto want = run(&layer_rows::kReference);
  for (const auto& [name, kernels] : Variants()) {
    ASSERT_EQ(run(kernels), want) << name << " C " << C << " trial " << trial;
  }
}

TEST(LayerRows, BoxRowVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(35);
  for (int32_t trial = 0; trial < 300; ++trial) {
    CheckBoxRowVariants<1>(rng, trial);
    CheckBoxRowVariants<2>(rng, trial);
  }
}

TEST(LayerRows, BoxPrefixRowAddsTheRoundedMeans) {
  std::mt19937 rng(23);
  for (int32_t trial = 0; trial < 200; ++trial) {
    const int32_t level = 1 + trial % 4, n = 1 + trial % 40;
    const int32_t max_box = (1 << (2 * level)) * kMaxV * 256;  // 2^level x 2^level pixels
    std::vector<int32_t> box(n);
    for (int32_t& b : box) {
      b = trial % 3 == 0 ? ((rng() & 1) ? max_box : -max_box)
                         : static_cast<int32_t>(rng() % (2 * uint32_t(max_box) + 1)) - max_box;
    }
    std::vector<uint32_t> p(n + 1);
    p[0] = rng();
    layer_rows::BoxPrefixRowC(box.data(), level, 0, n - 1, p.data());
    for (int32_t q = 0; q < n; ++q) {
      const double mean = std::floor(box[q] / static_cast<double>(1 << (2 * level)) + 0.5);
      ASSERT_EQ(static_cast<int32_t>(p[q + 1] - p[q]), static_cast<int32_t>(mean)) << trial;
    }
  }
}

TEST(LayerRows, LerpCompositeVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(31);
  for (int32_t trial = 0; trial < 300; ++trial) {
    const int32_t level = 1 + trial % 4, f = 1 << level, planes = 2 + trial % 2;
    const bool extreme = trial % 3 == 0;
    const int32_t n = 1 + static_cast<int32_t>(rng() % 120);
    // Exactly the taps the kernel may read, col[-1 .. ((n - 1 - f / 2) >> level) + 1], so an
    // overread shows under ASan.
    const int32_t low = ((n - 1 - f / 2) >> level) + 3;
    std::vector<int32_t> col(static_cast<size_t>(planes) * low);
    for (int32_t q = 0; q < low; ++q) {
      const LayerRow r = MakeLayerRow(rng, planes - 1, extreme);
      for (int32_t c = 0; c + 1 < planes; ++c) col[c * low + q] = r.colour[c];
      col[(planes - 1) * low + q] = r.alpha[0];
    }
    std::vector<uint8_t> frac(n);
    for (int32_t x = 0; x < n; ++x)
      frac[x] = static_cast<uint8_t>((((2 * x + 1 - f) * 128) >> level) & 255);
    const LayerRow behind = MakeLayerRow(rng, planes * n, extreme);
    const int32_t x0 = static_cast<int32_t>(rng() % n);
    std::vector<int32_t> want = behind.out;
    layer_rows::kReference.lerp_composite[planes - 2](col.data() + 1, low, frac.data(), level, x0,
                                                      n - 1, want.data(), n);
    for (const auto& [name, kernels] : Variants()) {
      std::vector<int32_t> got = behind.out;
      kernels->lerp_composite[planes - 2](col.data() + 1, low, frac.data(), level, x0, n - 1,
                                          got.data(), n);
      ASSERT_EQ(got, want) << name << " trial " << trial << " level " << level;
    }
  }
}

TEST(LayerRows, NormaliseVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(32);
  for (int32_t trial = 0; trial < 400; ++trial) {
    // Every reciprocal a kernel can have (total 256 .. 17 x 17 x 256, the twins' fallbacks
    // included), and any accumulator: the variants must agree even beyond the bounds.
    const uint32_t totals[] = {256, 257, 511, 512, 513, 256u * kCells};
    const uint32_t total = trial % 2 ? totals[trial / 2 % 6]
                                     : 256u + static_cast<uint32_t>(rng() % (256u * kCells - 255));
    const uint64_t rec = (uint64_t{1} << 40) / total;
    const int32_t shift = static_cast<int32_t>(rng() % 17), n = 1 + trial % 70;
    const int32_t x0 = static_cast<int32_t>(rng() % n);
    std::vector<uint32_t> acc(n);
    for (uint32_t& a : acc) {
      a = trial % 3 == 0 ? ((rng() & 1) ? total * 256 : static_cast<uint32_t>(INT32_MIN))
                         : static_cast<uint32_t>(rng());
    }
    std::vector<int32_t> want_a(n, 7), want_c(n, 7);
    layer_rows::kReference.normalise_alpha(acc.data(), rec, x0, n - 1, want_a.data());
    layer_rows::kReference.normalise_colour(acc.data(), rec, shift, x0, n - 1, want_c.data());
    for (const auto& [name, kernels] : Variants()) {
      std::vector<int32_t> got_a(n, 7), got_c(n, 7);
      kernels->normalise_alpha(acc.data(), rec, x0, n - 1, got_a.data());
      kernels->normalise_colour(acc.data(), rec, shift, x0, n - 1, got_c.data());
      ASSERT_EQ(got_a, want_a) << name << " trial " << trial;
      ASSERT_EQ(got_c, want_c) << name << " trial " << trial;
    }
  }
}

TEST(LayerRows, BlendAndBoxPrefixVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(33);
  for (int32_t trial = 0; trial < 300; ++trial) {
    const int32_t n = 1 + trial % 90, q0 = static_cast<int32_t>(rng() % n);
    const LayerRow ra = MakeLayerRow(rng, n, trial % 2 == 0),
                   rb = MakeLayerRow(rng, n, trial % 3 == 0);
    const int64_t fy = trial % 5 == 0 ? 255 : static_cast<int64_t>(rng() % 256);
    std::vector<int32_t> want(n + 2, 7);
    layer_rows::kReference.blend(ra.colour.data(), rb.colour.data(), fy, q0, n - 1,
                                 want.data() + 1);
    // Box sums of up to 16 x 16 pixels of |c| <= kMaxV x 256, every level.
    const int32_t level = 1 + trial % 4;
    const int32_t max_box = (1 << (2 * level)) * kMaxV * 256;
    std::vector<int32_t> box(n);
    for (int32_t& b : box) {
      b = trial % 3 == 0 ? ((rng() & 1) ? max_box : -max_box)
                         : static_cast<int32_t>(rng() % (2 * uint32_t(max_box) + 1)) - max_box;
    }
    std::vector<uint32_t> want_p(n + 1, 7);
    want_p[q0] = rng();
    const std::vector<uint32_t> start = want_p;
    layer_rows::kReference.box_prefix(box.data(), level, q0, n - 1, want_p.data());
    for (const auto& [name, kernels] : Variants()) {
      std::vector<int32_t> got(n + 2, 7);
      kernels->blend(ra.colour.data(), rb.colour.data(), fy, q0, n - 1, got.data() + 1);
      ASSERT_EQ(got, want) << name << " trial " << trial;
      std::vector<uint32_t> got_p = start;
      kernels->box_prefix(box.data(), level, q0, n - 1, got_p.data());
      ASSERT_EQ(got_p, want_p) << name << " trial " << trial;
    }
  }
}

TEST(LayerRows, ResolveVariantsEqualTheReference) {
  SkipWithoutVariants();
  std::mt19937 rng(34);
  for (int32_t trial = 0; trial < 300; ++trial) {
    const int32_t n = 1 + trial % 100;
    LayerRow r = MakeLayerRow(rng, n, trial % 3 == 0);
    std::vector<int16_t> v(n);
    for (int32_t x = 0; x < n; ++x) {
      v[x] = static_cast<int16_t>(static_cast<int32_t>(rng() % (2 * kMaxV + 1)) - kMaxV);
      // Mostly fully covered runs (the fast path), some partial and some empty pixels, and
      // composited values up to the bound |out| < 2^31 - 2^16.
      const uint32_t kind = rng() % 16;
      if (kind < 12 && trial % 4 != 1) r.alpha[x] = 65536;
      if (kind == 12) r.alpha[x] = 0;
      if (kind == 13) r.colour[x] = (rng() & 1) ? INT32_MAX - 65536 : -(INT32_MAX - 65536);
    }
    const int32_t bias = trial % 2 == 0 ? 0 : 128;
    std::vector<uint8_t> want(n);
    layer_rows::kReference.resolve(r.colour.data(), r.alpha.data(), v.data(), n, bias, want.data());
    for (const auto& [name, kernels] : Variants()) {
      std::vector<uint8_t> got(n);
      kernels->resolve(r.colour.data(), r.alpha.data(), v.data(), n, bias, got.data());
      ASSERT_EQ(got, want) << name << " trial " << trial;
    }
  }
}

TEST(LayerRows, BestKernelsAreOneOfTheVariants) {
  const Kernels& best = layer_rows::BestKernels();
  bool found = false;
  for (const auto& [name, kernels] : Variants()) found = found || kernels == &best;
  EXPECT_TRUE(found);
  EXPECT_EQ(&best, &layer_rows::BestKernels());  // decided once
}

}  // namespace
}  // namespace lb

namespace lb::layer_rows {
namespace {

// The table a plane is carved with follows what the firmware read of the processor
// (algo/core/cpu.h): nothing read means the C reference, even where the build could do more.
TEST(LayerRows, TheTableFollowsTheFeaturesHandedIn) {
  const CpuFeatures before = CurrentCpu();
  SetCpu(CpuFeatures{});
  EXPECT_EQ(&BestKernels(), &kReference);
  CpuFeatures simd;
  simd.avx2 = Avx2Kernels() != nullptr;
  simd.neon = !simd.avx2 && NeonKernels() != nullptr;
  SetCpu(simd);
  const Kernels* expected = simd.avx2 ? Avx2Kernels() : (simd.neon ? NeonKernels() : &kReference);
  EXPECT_EQ(&BestKernels(), expected);
  SetCpu(before);
}

}  // namespace
}  // namespace lb::layer_rows
